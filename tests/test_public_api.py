"""``import ngdual as nd``: a small documented public API, loaded lazily.

Every name of ``nd.__all__`` resolves and carries a docstring; importing ngdual imports
neither NGSolve nor matplotlib (the command line stays fast and a notebook keeps its
matplotlib backend); the five lines of the README solve Example 3.46 with Coulomb friction.
"""

import json
import subprocess
import sys

import pytest

import ngdual as nd


def test_every_public_name_resolves_and_has_a_docstring():
    assert len(nd.__all__) == len(set(nd.__all__)) and 10 <= len(nd.__all__) <= 40
    for name in nd.__all__:
        value = getattr(nd, name)
        if name == "__version__":
            assert isinstance(value, str) and value.count(".") >= 1
            continue
        doc = getattr(value, "__doc__", None)
        assert doc and doc.strip(), f"nd.{name} has no docstring"


def test_public_names_are_the_pipeline_functions():
    from ngdual import (
        accuracy,
        afem,
        boundary,
        estimator,
        marking,
        mesh,
        quantities,
        scene,
        solvers,
        trace,
    )

    assert nd.solve is accuracy.solve
    assert nd.load_scene is scene.load_scene and nd.Scene is scene.Scene
    assert nd.adapt is afem.adapt and nd.estimate is estimator.estimate
    assert nd.mark is marking.mark and nd.contact_traces is trace.contact_traces
    assert nd.norms is quantities.norms and nd.fields is quantities.fields
    # the steps of the adaptive loop, to write it by hand (tutorial 07)
    assert nd.solve_on_mesh is solvers.solve_on_mesh and nd.build_mesh is mesh.build_mesh
    assert nd.refine_with_boundary is afem.refine_with_boundary
    assert nd.BoundaryMeshes is boundary.BoundaryMeshes


def test_the_names_the_tutorials_take_the_method_apart_with():
    from ngdual import expr, forms, friction, mesh, rates, scene, solvers, verification
    from ngdual.studies import tutorials

    assert nd.assemble is forms.assemble and nd.Expression is expr.Expression
    assert nd.Lesson is tutorials.Lesson and nd.rates is rates
    assert nd.friction_forms is friction.build_friction_forms and nd.mesh_arrays is mesh.mesh_arrays
    assert nd.scene is scene and nd.solvers is solvers and nd.verification is verification
    # a public subpackage comes with its modules: Algorithm 3.38, the QPs, Williams' corner
    assert nd.solvers.uzawa.uzawa and nd.solvers.qp.solve_qp and nd.solvers.nested.nested_uzawa
    assert nd.verification.corner.l_shape_scene and nd.verification.infsup.gram_matrix


def test_a_public_subpackage_brings_its_modules_in_a_fresh_process():
    code = ("import ngdual as nd; "
            "print(nd.verification.overkill.__name__, nd.solvers.projections.__name__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.split() == ["ngdual.verification.overkill", "ngdual.solvers.projections"]


def test_dir_lists_the_public_names_and_unknown_names_raise():
    assert set(nd.__all__) <= set(dir(nd))
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        nd.no_such_name  # noqa: B018


def test_submodules_are_reachable_as_attributes():
    assert nd.quantities.norms is nd.norms


def test_importing_ngdual_imports_neither_ngsolve_nor_pyplot():
    code = ("import sys, json, ngdual; print(json.dumps({m: m in sys.modules for m in "
            "('ngsolve', 'netgen', 'matplotlib', 'matplotlib.pyplot')}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert not any(json.loads(out).values()), out


def test_a_scene_loads_without_ngsolve():
    code = ("import sys, ngdual as nd; nd.load_scene('thesis-3.46-coulomb'); "
            "print('ngsolve' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "False"


def test_the_readme_example_solves_example_3_46_with_coulomb_friction():
    scene = nd.load_scene("thesis-3.46-coulomb", ["geometry.level=2"])
    solution = nd.solve(scene)
    assert solution.converged
    record = nd.result_record(solution)
    assert record["dofs"]["X"] == 680                         # Table 3.1, level 2
    assert record["contact"]["nodes_in_contact"] > 0
    traces = nd.contact_traces(solution)
    force = nd.force_balance(solution).multiplier_force      # on the h~ hats, n = (0, -1)
    # the foundation pushes up; the load and gap are even in x, but the diagonals of the
    # structured mesh of Example 3.46 all lean one way (it is not mirror-symmetric), so the
    # discrete friction force is not exactly zero (0.7 % of the normal force on level 2)
    assert force[1] > 0 and abs(force[0]) < 0.02 * force[1]
    assert traces.lam_n.min() >= -1e-12                      # lambda_n >= 0 (3.62)


def test_the_command_line_prints_the_version():
    out = subprocess.run([sys.executable, "-m", "ngdual", "--version"], capture_output=True,
                         text=True, check=True).stdout
    assert out.strip() == f"ngdual {nd.__version__}"
