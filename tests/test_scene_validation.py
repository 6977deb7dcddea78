"""Bad scenes fail at validation with one line naming the field; the CLI exits 2, writes nothing."""

import dataclasses

import pytest

from ngdual.cli import main
from ngdual.scene import Friction, SceneError, Solver, load_scene, shipped_scenes, validate

BAD = [
    (["boundary.contact=['floor']"], "boundary.contact", "unknown boundary label"),
    (["boundary.dirichlet=['left']"], "boundary", "'right' has no condition"),
    (["boundary.neumann=['top', 'right']", "boundary.dirichlet=['left']"], "contact.ends",
     "touches"),
    (["contact.ends='both'"], "contact.ends", "unknown choice"),
    (["contact.ends='consistent'", "loads.displacement=['0', '-0.02']"], "contact.gap",
     "need g >= u_D.n"),
    (["contact.foundation={point = [0, -1], normal = [0, 1]}"], "contact.gap", "not both"),
    (["geometry.arcs={bottom = [0, 3]}"], "geometry.arcs", "kind"),
    (["material.E=0"], "material.E", "positive"),
    (["material.E=-2e5"], "material.E", "positive"),
    (["material.nu=0.5"], "material.nu", "(-1, 0.5)"),
    (["material.nu=-1"], "material.nu", "(-1, 0.5)"),
    (["friction.mu=-0.1"], "friction.mu", ">= 0"),
    (["contact.gap='x - 1'"], "contact.gap", "negative gap"),
    (["contact.gap='foo(x)'"], "contact.gap", "unknown name"),
    (["friction.law='stick'"], "friction.law", "unknown friction law"),
    (["solver.eps=0"], "solver.eps", "positive"),
    (["solver.rho=-1"], "solver.rho", "positive"),
    (["solver.rho1=0"], "solver.rho1", "positive"),
    (["solver.eps2=-1e-6"], "solver.eps2", "positive"),
    (["solver.max_iter=0"], "solver.max_iter", "positive"),
    (["solver.metric='l2'"], "solver.metric", "unknown metric"),
    (["contact.hhat_factor=3"], "contact.hhat_factor", "must be 1"),
    (["material.youngs=1"], "material.youngs", "unknown key"),
    (["loads.traction=['0']"], "loads.traction", "pair"),
    (["geometry.level=0"], "geometry.level", "positive"),
    (["geometry.level=2.5"], "geometry.level", "integer"),
    (["material.E=1e-300"], "material.E", "outside"),
    (["material.E='2e5'"], "material.E", "must be a number"),
    (["solver.rho2='abc'"], "solver.rho2", "must be a number"),
    (["friction.law='tresca'"], "friction.bound", "needs a bound"),
    (["friction.law='coulomb'"], "friction.mu", "mu > 0"),
    (["friction.law='tresca'", "friction.bound='-1'"], "friction.bound", ">= 0"),
    (["contact.gap='10**10**10'"], "contact.gap", "overflows"),
    (["contact.gap='x*True'"], "contact.gap", "not a number"),
    (["loads.traction=['0', '-800/x']"], "loads.traction[1]", "not integrable"),
    (["loads.traction=['0', 'ifpos(x, 1)']"], "loads.traction[1]", "takes 3 arguments"),
    (["loads.displacement=['0', 'log(y + 1)']"], "loads.displacement[1]", "not finite"),
    # a setting the chosen method or friction law ignores is an error, also at its default
    (["solver.rho=2"], "solver.rho", "does nothing with solver.method = 'auto'"),
    (["solver.rho=1.0"], "solver.rho", "does nothing with solver.method = 'auto'"),
    (["solver.method='active-set'", "solver.loop_order='contact-outer'"], "solver.loop_order",
     "does nothing with solver.method = 'active-set'"),
    (["friction.mu=0.3"], "friction.mu", "does nothing with friction.law = 'none'"),
    (["friction.normal_stress='fine-edges'"], "friction.normal_stress", "only 'coulomb'"),
    (["friction.bound='100'"], "friction.bound", "only 'tresca'"),
    (["friction.law='tresca'", "friction.bound='100'", "friction.mu=0.5"], "friction.mu",
     "does nothing with friction.law = 'tresca'"),
    (["friction.law='coulomb'", "friction.mu=0.5", "friction.bound='100'"], "friction.bound",
     "does nothing with friction.law = 'coulomb'"),
]


@pytest.mark.parametrize("overrides, field, words", BAD)
def test_bad_scene_raises_one_line_error_naming_the_field(overrides, field, words):
    with pytest.raises(SceneError) as info:
        load_scene("thesis-3.46-frictionless", overrides)
    message = str(info.value)
    assert info.value.field == field
    assert message.startswith(field + ":")
    assert words in message
    assert "\n" not in message


@pytest.mark.parametrize("overrides, field, words", BAD[:6])
def test_cli_exits_2_and_writes_no_result(tmp_path, capsys, overrides, field, words):
    args = ["solve", "thesis-3.46-frictionless", "--level", "1", "--out", str(tmp_path)]
    for item in overrides:
        args += ["--set", item]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and field in err
    assert not any(tmp_path.iterdir())


def test_a_setting_without_effect_is_named_only_once_with_its_bad_value_first():
    """rho = 0 under the active-set solver: the bad value is the one problem reported."""
    with pytest.raises(SceneError) as info:
        load_scene("thesis-3.46-frictionless", ["solver.rho=0"])
    assert info.value.fields == ["solver.rho"] and "positive" in str(info.value)


def test_switching_a_shipped_coulomb_scene_to_no_friction_names_its_coefficient():
    with pytest.raises(SceneError) as info:
        load_scene("thesis-3.46-coulomb", ["friction.law='none'"])
    assert info.value.fields == ["friction.mu"]


def test_uzawa_accepts_the_settings_of_both_algorithms():
    """Algorithm 3.38 or 3.41 follows from the friction law: one set of Uzawa parameters
    serves every law (the shipped scenes and the tuned steps of ngdual bench)."""
    for name in ("thesis-3.46-frictionless", "thesis-3.46-coulomb"):
        scene = load_scene(name, ["solver.method='uzawa'", "solver.rho=1.1", "solver.rho1=1.2",
                                  "solver.eps2=1e-8"])
        assert scene.solver.rho1 == 1.2


def test_a_scene_built_in_python_is_checked_by_what_differs_from_the_defaults():
    scene = load_scene("thesis-3.46-frictionless")
    validate(scene)                       # every setting at its default: nothing to report
    bad = dataclasses.replace(scene, solver=Solver(rho=2.0),
                              friction=Friction(law="none", mu=0.3))
    with pytest.raises(SceneError) as info:
        validate(bad)
    assert info.value.fields == ["solver.rho", "friction.mu"]


def test_unknown_scene_name_lists_the_shipped_ones():
    with pytest.raises(SceneError, match="thesis-3.46-frictionless"):
        load_scene("thesis-3.46-nonexistent")


def test_polygon_must_be_counter_clockwise(tmp_path):
    path = tmp_path / "cw.toml"
    path.write_text("""
[geometry]
kind = "polygon"
points = [[0, 0], [0, 1], [1, 1], [1, 0]]
labels = ["a", "b", "c", "d"]
[boundary]
dirichlet = ["a", "b", "c", "d"]
""")
    with pytest.raises(SceneError, match="geometry.points"):
        load_scene(path)


@pytest.mark.parametrize("name", shipped_scenes())
def test_every_shipped_scene_loads_and_validates(name):
    scene = load_scene(name)
    assert scene.name == name


def test_friction_without_contact_is_rejected():
    with pytest.raises(SceneError, match="friction.law"):
        load_scene("thesis-3.46-coulomb", ["boundary.contact=[]",
                                           "boundary.dirichlet=['left', 'right', 'bottom']"])


def test_formulas_with_transcendental_functions_assemble():
    import ngsolve as ngs

    from ngdual.expr import Expression

    cf = Expression("sin(x) + exp(y) * cos(pi*x) + sqrt(abs(x)) + log(2) + atan(y)").coefficient()
    mesh = __import__("ngdual.mesh", fromlist=["x"]).thesis_mesh(1)
    value = cf(mesh(0.5, 0.25))
    expected = Expression("sin(x) + exp(y) * cos(pi*x) + sqrt(abs(x)) + log(2) + atan(y)").numpy(
        __import__("numpy").array([0.5]), __import__("numpy").array([0.25]))[0]
    assert abs(value - expected) < 1e-12
    assert isinstance(cf, ngs.CoefficientFunction)


def test_nonzero_displacement_at_the_ends_of_gamma_c_is_rejected():
    with pytest.raises(SceneError, match="loads.displacement"):
        load_scene("thesis-3.46-frictionless", ["loads.displacement=['0.001', '0']"])


BLOCK = {"kind": "polygon", "points": [[-1.0, 0.0], [1.0, 0.0], [1.0, 1.0], [-1.0, 1.0]],
         "labels": ["bottom", "right", "top", "left"], "maxh": 0.5}
BAD_GEOMETRY = [
    # an arc whose end points are not equidistant from its centre
    ({"arcs": {"bottom": [0.0, 3.0]}, "points": [[-1.0, 0.0], [1.0, 0.1], [1.0, 1.0],
                                                [-1.0, 1.0]]}, {}, "geometry.arcs.bottom",
     "equal distances"),
    # an arc bulging so far that it crosses the top side
    ({"arcs": {"bottom": [0.0, 0.0]}}, {}, "geometry.arcs.bottom", "180 degrees"),
    ({"arcs": {"bottom": [0.0, -0.05]},
      "points": [[-1.0, 0.0], [1.0, 0.0], [1.0, 0.5], [-1.0, 0.5]]}, {}, "geometry.arcs",
     "intersects itself"),
    ({"arcs": {"floor": [0.0, 3.0]}}, {}, "geometry.arcs.floor", "unknown side label"),
    ({}, {"foundation": {"point": [0.0, 0.2], "normal": [0.0, 1.0]}}, "contact.foundation",
     "cuts the body"),
    ({}, {"foundation": {"point": [0.0, -1.0], "normal": [1.0, 0.0]}}, "contact.foundation",
     "cuts the body"),
    ({}, {"foundation": {"point": [0.0, 0.0], "normal": [0.0, 0.0]}},
     "contact.foundation.normal", "zero"),
    # a V-shaped notch in the contact side: re-entrant kink
    ({"points": [[-1.0, 0.0], [0.0, 0.5], [1.0, 0.0], [1.0, 1.0], [-1.0, 1.0]],
      "labels": ["c1", "c2", "right", "top", "left"]}, {}, "boundary.contact", "re-entrant"),
]


@pytest.mark.parametrize("geometry, contact, field, words", BAD_GEOMETRY)
def test_bad_geometry_and_foundation_are_refused_naming_the_field(geometry, contact, field,
                                                                   words):
    from ngdual.scene import Contact, Geometry, Scene, validate
    geo = Geometry(**{**BLOCK, **geometry})
    contact_labels = [lab for lab in geo.labels if lab.startswith("c")] or ["bottom"]
    boundary = {"contact": contact_labels, "dirichlet": ["top"],
                "neumann": [lab for lab in geo.labels if lab in ("left", "right")]}
    scene = Scene("bad", geo, boundary, contact=Contact(**contact))
    with pytest.raises(SceneError) as info:
        validate(scene)
    assert info.value.field == field, str(info.value)
    assert words in str(info.value)


def test_contact_sides_meeting_each_other_need_no_end_condition():
    """Gamma_C split where the load changes: the end checks apply only where Gamma_C meets
    Gamma_D or Gamma_N, not where two contact sides meet."""
    from ngdual.scene import Geometry, Scene, validate
    geo = Geometry(kind="polygon", points=[[-1.0, 0.0], [0.0, 0.0], [1.0, 0.0], [1.0, 1.0],
                                           [-1.0, 1.0]],
                   labels=["c1", "c2", "right", "top", "left"], maxh=0.5)
    scene = Scene("split", geo, {"contact": ["c1", "c2"], "dirichlet": ["left", "right"],
                                 "neumann": ["top"]})
    scene.loads.displacement = ["0", "y"]  # vanishes at the corners (+-1, 0) only
    validate(scene)


def test_several_problems_in_one_scene_are_reported_together():
    with pytest.raises(SceneError) as info:
        load_scene("thesis-3.46-frictionless", ["material.E=0", "material.nu=0.7",
                                                "solver.eps=-1", "contact.gap='x +'"])
    assert set(info.value.fields) == {"material.E", "material.nu", "solver.eps", "contact.gap"}
    lines = str(info.value).splitlines()
    assert lines[0] == "4 problems in the scene:" and len(lines) == 5
    assert info.value.field == info.value.fields[0]


def test_a_scene_must_state_its_geometry():
    """No [geometry] table (or no kind) is refused; it never becomes the thesis rectangle."""
    from ngdual.scene import scene_from_dict

    boundary = {"dirichlet": ["left", "right", "top", "bottom"]}
    with pytest.raises(SceneError, match="geometry: missing table"):
        scene_from_dict({"boundary": boundary})
    with pytest.raises(SceneError, match="geometry.kind: missing"):
        scene_from_dict({"geometry": {"level": 2}, "boundary": boundary})
    scene = scene_from_dict({"geometry": {"kind": "thesis-3.46", "level": 2},
                             "boundary": boundary})
    assert scene.geometry.kind == "thesis-3.46" and scene.geometry.level == 2


@pytest.mark.parametrize("points, words", [
    ([[0, 0], [1, 0], [1, 0], [1, 1], [0, 1]], "points[1] and points[2] coincide"),
    ([[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]], "points[0] and points[4] coincide"),
    ([[0, 0], [2, 0], [1, 1], [2, 2], [0, 2], [1, 1]], "the boundary touches itself"),
    ([[0, 0], [2, 0], [2, 2], [1, -1], [0, 2]], "intersects itself"),
])
def test_degenerate_polygons_never_reach_netgen(points, words):
    """A zero-length side crashed netgen (segfault); a positive-area bow-tie hung it."""
    from ngdual.mesh import build_mesh
    from ngdual.scene import Geometry

    geo = Geometry(kind="polygon", points=points, labels=[f"s{i}" for i in range(len(points))])
    with pytest.raises(SceneError, match="geometry.points") as info:
        build_mesh(geo)
    assert words in str(info.value)


def test_integrable_singularities_pass_and_poles_do_not():
    ok = ["-800/sqrt(abs(x - 0.3))", "-800*log(abs(x - 0.3))", "-800*ifpos(x - 0.3, 1, 0)",
          "-800*exp(-1e4*(x - 0.3)**2)"]
    for formula in ok:
        load_scene("thesis-3.46-frictionless", [f"loads.traction=['0', '{formula}']"])
    for formula in ("-800/(x - 0.3)", "1/(x*x - 0.09)", "3 + 1e-3/(x - 0.123)"):
        with pytest.raises(SceneError, match="not integrable") as info:
            load_scene("thesis-3.46-frictionless", [f"loads.traction=['0', '{formula}']"])
        assert info.value.field == "loads.traction[1]"


def test_constants_are_folded_once_in_floating_point():
    from ngdual.expr import Expression, ExpressionError

    assert Expression("2**10 + pi").constant == 1024 + __import__("math").pi
    assert Expression("x**10**10").constant is None   # x-dependent: evaluated in floats
    for text, words in (("9**9**9", "overflows"), ("exp(1000)", "overflows"),
                        ("0**-1", "division by zero"), ("(-8)**(1/3)", "not a real number"),
                        ("log(0)", "not defined"), ("max(x)", "takes 2 arguments")):
        with pytest.raises(ExpressionError, match=words):
            Expression(text)


def test_a_scene_changed_after_loading_is_validated_again():
    from ngdual.solvers import solve_scene

    scene = load_scene("thesis-3.46-frictionless")
    scene.material.nu = 0.5
    with pytest.raises(SceneError, match="material.nu"):
        solve_scene(scene, 1)


def test_the_size_estimate_matches_the_meshes():
    """Exact for Example 3.46 (Table 3.1); within a factor 2 for netgen's polygons."""
    from ngdual.budget import estimate
    from ngdual.mesh import build_mesh

    thesis = load_scene("thesis-3.46-frictionless").geometry
    for level in (1, 2, 3):
        assert estimate(thesis, level).elements == build_mesh(thesis, level).ne
    for name in ("punch-on-foundation", "hertz-cylinder", "flat-punch", "wedge"):
        geo = load_scene(name).geometry
        ne = build_mesh(geo, 1).ne
        assert 0.5 < estimate(geo, 1).elements / ne < 2, name
