"""Validation of a whole scene: every problem reported together, one line each, naming its field."""

from __future__ import annotations

import dataclasses

import numpy as np

from .contact import validate_contact, validate_gap_and_bound
from .domain import validate_boundary, validate_formulas_on_sides, validate_geometry
from .errors import Problems, SceneError, SceneTypeError
from .tables import (
    BENCHMARK_KINDS,
    CONTACT_ENDS,
    DISCRETE_GAPS,
    FRICTION_LAWS,
    FRICTION_METRICS,
    LENGTH_UNITS,
    LOOP_ORDERS,
    METRICS,
    MULTIPLIER_FAMILIES,
    NORMAL_STRESSES,
    ORDERS,
    SECTIONS,
    SOLVER_METHODS,
    STRESS_UNITS,
    Contact,
    Discretisation,
    Material,
    Scene,
    Solver,
    Units,
)
from .values import expression, finite, pair, positive, show, tractions, type_problems


def check_level(level, field_name: str = "level", optional: bool = False) -> int | None:
    """``level`` if it is a mesh level (an integer >= 1; None too if ``optional``)."""
    if level is None and optional:
        return None
    if isinstance(level, bool) or not isinstance(level, (int, np.integer)):
        raise SceneTypeError(field_name, f"must be an integer >= 1{' or None' * optional}, "
                                         f"got {show(level)}")
    if level < 1:
        raise SceneError(field_name, f"must be >= 1 (level 1 is the initial mesh), got {level}")
    return int(level)


def ensure_valid(scene: Scene) -> None:
    """:func:`validate` ``scene`` unless it was validated and has not changed since."""
    if not isinstance(scene, Scene):
        raise SceneTypeError("scene", f"must be an ngdual.scene.Scene (see load_scene), got "
                                      f"{type(scene).__name__}")
    key = repr(scene)
    if scene.__dict__.get("_validated_as") != key:
        validate(scene)
        scene.__dict__["_validated_as"] = key


E_RANGE = (1e-30, 1e30)  # beyond, C^-1 ~ 1/E and sigma ~ E reach the ends of double precision


def validate(scene: Scene) -> None:
    """Raise one :class:`SceneError` listing every problem found in ``scene``.

    Independent settings are checked independently, so a scene with several mistakes
    gets them all reported at once, each naming its field; checks that need a sound
    geometry and boundary (sampling the formulas on Gamma_N, Gamma_D, Gamma_C) run only
    when those are sound.
    """
    if not isinstance(scene, Scene):
        raise SceneTypeError("scene", f"must be an ngdual.scene.Scene (see load_scene), got "
                                      f"{type(scene).__name__}")
    problems = Problems()
    for f, m in type_problems(scene):
        problems.add(f, m)
    wrong = {f.split(".")[0] for f in (p[0] for p in problems.found)}
    ok = {section: section not in wrong for section in ("geometry", "boundary", *SECTIONS)}
    if ok["geometry"]:
        ok["geometry"] = problems.run(validate_geometry, scene.geometry)
    if ok["geometry"] and ok["boundary"]:
        ok["boundary"] = problems.run(validate_boundary, scene)
    if ok["material"]:
        problems.run(_validate_material, scene.material)
    loads = {}
    if ok["loads"]:
        for key in ("body_force", "displacement"):
            loads[key] = problems.run(pair, getattr(scene.loads, key), f"loads.{key}",
                                      value=True)
        loads["traction"] = problems.run(tractions, scene.loads.traction,
                                         scene.labels("neumann") if ok["boundary"] else None,
                                         value=True)
        ok["loads"] = all(v is not None for v in loads.values())
    if ok["contact"]:
        ok["contact"] = problems.run(_validate_contact_settings, scene.contact)
    if ok["friction"]:
        ok["friction"] = problems.run(_validate_friction_settings, scene)
    if ok["solver"]:
        _validate_solver(scene.solver, problems)
    if isinstance(scene.units, Units):  # a bad type of one unit is reported above
        _validate_units(scene.units, problems)
    if ok["benchmark"] and ok["friction"]:
        problems.run(_validate_benchmark, scene)
    if ok["discretisation"] and ok["friction"] and ok["solver"] and ok["contact"]:
        problems.run(_validate_discretisation, scene)
    if ok["solver"] and ok["friction"] and scene.solver.method in SOLVER_METHODS:
        reported = {f for f, _ in problems.found}
        for f, m in _settings_without_effect(scene):
            if f not in reported:  # one problem per field: its bad value comes first
                problems.add(f, m)
    if all(ok[k] for k in ("geometry", "boundary", "loads", "contact", "friction")):
        if problems.run(validate_formulas_on_sides, scene, loads) \
                and problems.run(validate_contact, scene, loads["displacement"]):
            problems.run(validate_gap_and_bound, scene)
    problems.raise_any()
    scene.__dict__["_validated_as"] = repr(scene)  # for ensure_valid


def _validate_material(mat: Material) -> None:
    problems = Problems()
    with problems.check():
        positive(mat.E, "material.E")
        if not E_RANGE[0] <= mat.E <= E_RANGE[1]:
            raise SceneError("material.E", f"{mat.E:g} is outside [{E_RANGE[0]:g}, "
                                           f"{E_RANGE[1]:g}], where the compliance 1/E and "
                                           "the stresses stay within double precision; "
                                           "rescale the units")
    if not -1 < mat.nu < 0.5:
        problems.add("material.nu", f"Poisson's ratio must lie in (-1, 0.5), got {show(mat.nu)}")
    problems.raise_any()


def _validate_contact_settings(con: Contact) -> None:
    problems = Problems()
    with problems.check():
        expression(con.gap_formula, "contact.gap")
    if con.ends not in CONTACT_ENDS:
        problems.add("contact.ends", f"unknown choice {show(con.ends)}; use one of "
                                     + ", ".join(CONTACT_ENDS))
    if con.discrete_gap not in DISCRETE_GAPS:
        problems.add("contact.discrete_gap", f"unknown choice {show(con.discrete_gap)}; use "
                                             "one of " + ", ".join(DISCRETE_GAPS))
    with problems.check():
        positive(con.htilde_factor, "contact.htilde_factor", integer=True)
    if con.hhat_factor not in (1, 2):
        problems.add("contact.hhat_factor", f"must be 1 (h^ = h~) or 2 (h^ = 2h~), "
                                            f"got {show(con.hhat_factor)}")
    problems.raise_any()


def _validate_friction_settings(scene: Scene) -> None:
    fr = scene.friction
    problems = Problems()
    if fr.law not in FRICTION_LAWS:
        problems.add("friction.law", f"unknown friction law {show(fr.law)}; use one of "
                                     + ", ".join(FRICTION_LAWS))
    elif fr.law != "none" and not scene.has_contact:
        problems.add("friction.law", f"{show(fr.law)} friction needs a contact boundary "
                                     "(boundary.contact is empty)")
    if not (finite(fr.mu) and fr.mu >= 0):
        problems.add("friction.mu", f"friction coefficient must be >= 0, got {show(fr.mu)}")
    elif fr.law == "coulomb" and fr.mu == 0:
        problems.add("friction.mu", "Coulomb friction needs a coefficient mu > 0 (mu = 0 is "
                                    "frictionless: use friction.law = \"none\")")
    if fr.normal_stress not in NORMAL_STRESSES:
        problems.add("friction.normal_stress", f"unknown choice {show(fr.normal_stress)}; use "
                                               "one of " + ", ".join(NORMAL_STRESSES))
    with problems.check():
        expression(fr.bound, "friction.bound")
    problems.raise_any()


def _validate_discretisation(scene: Scene) -> None:
    """The order k and the multiplier family, and what each family can solve."""
    disc, problems = scene.discretisation, Problems()
    if isinstance(disc.order, bool) or disc.order not in ORDERS:
        problems.add("discretisation.order", f"the polynomial order k must be one of "
                                             f"{', '.join(map(str, ORDERS))}, got "
                                             f"{show(disc.order)}")
    if disc.multipliers not in MULTIPLIER_FAMILIES:
        problems.add("discretisation.multipliers", f"unknown family {show(disc.multipliers)}; "
                                                   "use one of " + ", ".join(MULTIPLIER_FAMILIES))
    problems.raise_any()
    if disc.family == "coarse" and disc.order > 0:
        if scene.friction.law != "none":
            problems.add("friction.law", f"friction at order {disc.order} bounds lambda_t by the "
                         "normal moments of the facet multipliers on the fine edges; the coarse "
                         "multipliers of degree k + 1 have no friction bound nu on the h^ mesh "
                         "of that degree: use discretisation.multipliers = \"facet\" (or "
                         "\"auto\") for friction at order k")
    if disc.family == "facet":
        if scene.friction.law == "coulomb" and "normal_stress" in given_keys(scene, "friction"):
            problems.add("friction.normal_stress", "chooses the |sigma_n| of the thesis' "
                         "Coulomb bound on the h^ edges; the facet multipliers bound every "
                         "Bernstein coefficient by mu_f times its own normal moment, so it "
                         "does nothing with discretisation.multipliers = \"facet\"; remove it")
        for f, m in _facet_contact_settings(scene.contact):
            problems.add(f, m)
    if scene.contact.ends == "thesis" and (disc.order > 0 or disc.family == "facet"):
        problems.add("contact.ends", _thesis_ends_elsewhere(disc))
    problems.raise_any()


def _thesis_ends_elsewhere(disc: Discretisation) -> str:
    """Why ``contact.ends = "thesis"`` is refused at ``disc``: one rule for both families.

    The thesis' C_h~ of (3.61) sets the P1 hats of order 0 to zero at every end of Gamma_C, a
    property of that space kept to reproduce the thesis' tables (and inconsistent where
    g - u_D.n is not zero at a clamped end: sigma leaves L2 there). At order k >= 1 there is
    no thesis table to reproduce, and the facet multipliers have no end value to set; both
    families take the end values the data prescribe, ``"consistent"``.
    """
    why = ("the facet multipliers have no value at an end of Gamma_C to prescribe"
           if disc.family == "facet" else "there is no thesis table to reproduce, only the "
           "force its zero end values put into the clamped corners")
    return ('"thesis" (lambda = 0 at every end of Gamma_C, C_h~ of (3.61)) is the thesis\' '
            "space of order 0 with the coarse multipliers; at discretisation.order = "
            f'{disc.order} with discretisation.multipliers = "{disc.family}" {why}: set '
            'contact.ends = "consistent"')


def _facet_contact_settings(con: Contact) -> list[tuple[str, str]]:
    """``(field, message)`` for every coarse mesh size that the facet multipliers would ignore.

    The facet multipliers live on the fine edges: there is no h~ or h^ mesh to size, so
    values other than the defaults would do nothing (``contact.ends`` is the one rule of
    :func:`_thesis_ends_elsewhere`, for both families).
    """
    default, found = Contact(), []
    for key, what in (("htilde_factor", "h~ = htilde_factor h"),
                      ("hhat_factor", "h^ = hhat_factor h~")):
        if getattr(con, key) != getattr(default, key):
            found.append((f"contact.{key}", f"{what} sizes a coarse mesh of the thesis' "
                          "multipliers; the facet multipliers live on the fine edges and have "
                          "none, so it does nothing with discretisation.multipliers = "
                          f"\"facet\"; remove it (default {getattr(default, key)})"))
    return found


def _validate_solver(sol: Solver, problems: Problems) -> None:
    choices = {"method": SOLVER_METHODS, "metric": METRICS, "loop_order": LOOP_ORDERS,
               "friction_metric": FRICTION_METRICS}
    for key, allowed in choices.items():
        value = getattr(sol, key)
        if value not in allowed:
            problems.add(f"solver.{key}", f"unknown {key.replace('_', ' ')} {show(value)}; use "
                                          "one of " + ", ".join(allowed))
    for key in ("rho", "eps", "rho1", "rho2", "eps1", "eps2"):
        if problems.run(positive, getattr(sol, key), f"solver.{key}") and key == "rho2" \
                and not sol.rho2 < 2:
            problems.add("solver.rho2", f"rho2 = {sol.rho2} is outside (0, 2), where the nu "
                                        "iteration converges (it is relative to the stability "
                                        "bound)")
    problems.run(positive, sol.max_iter, "solver.max_iter", integer=True)
    if not (isinstance(sol.condensed, bool) or sol.condensed == "auto"):
        problems.add("solver.condensed", f"must be true, false or \"auto\", got "
                                         f"{show(sol.condensed)}")


def _validate_units(units: Units, problems: Problems) -> None:
    for key, allowed in (("length", LENGTH_UNITS), ("stress", STRESS_UNITS)):
        value = getattr(units, key)
        if isinstance(value, str) and value not in allowed:
            problems.add(f"units.{key}", f"unknown {key} unit {show(value)}; use one of "
                                         + ", ".join(allowed) + " (or leave it out: no unit)")


# The parameters each analytic solution reads (besides [material] and, for
# Cattaneo-Mindlin, friction.mu).
BENCHMARK_READS = {"none": ("kind",), "hertz": ("kind", "radius", "center"),
                   "cattaneo-mindlin": ("kind", "radius", "center"),
                   "flat-punch": ("kind", "half_width", "center"),
                   "wedge": ("kind", "slope", "center")}


def _validate_benchmark(scene: Scene) -> None:
    """The ``[benchmark]`` table: a known kind, the parameters it reads and no others."""
    bench = scene.benchmark
    if bench.kind not in BENCHMARK_KINDS:
        raise SceneError("benchmark.kind", f"unknown analytic solution {show(bench.kind)}; use "
                                           "one of " + ", ".join(BENCHMARK_KINDS))
    problems = Problems()
    reads = BENCHMARK_READS[bench.kind]
    for key in ("radius", "half_width", "slope"):
        if key in reads and getattr(bench, key) is None:
            problems.add(f"benchmark.{key}", f"missing: {bench.kind!r} needs it (a positive "
                                             "number)")
        elif key in reads:
            problems.run(positive, getattr(bench, key), f"benchmark.{key}")
    if "center" in reads and not (isinstance(bench.center, (list, tuple))
                                  and len(bench.center) == 2
                                  and all(finite(v) for v in bench.center)):
        problems.add("benchmark.center", f"must be a point [x, y], got {show(bench.center)}")
    for key in sorted(given_keys(scene, "benchmark") - set(reads)):
        problems.add(f"benchmark.{key}", f"does nothing with benchmark.kind = {bench.kind!r}, "
                     "which reads " + (", ".join(reads[1:]) or "nothing") + "; remove it")
    if bench.kind != "none" and not scene.has_contact:
        problems.add("benchmark.kind", f"{bench.kind!r} is a contact solution: the scene needs "
                                       "a contact boundary (boundary.contact is empty)")
    if bench.kind == "cattaneo-mindlin" and scene.friction.law != "coulomb":
        problems.add("benchmark.kind", "'cattaneo-mindlin' needs Coulomb friction "
                                       f"(friction.law = \"coulomb\"), got {scene.friction.law!r}")
    problems.raise_any()


# The settings each choice reads. "uzawa" reads those of Algorithm 3.38 or of Algorithm 3.41
# (Remark 3.45), whichever the friction law calls for: one set of Uzawa parameters serves
# the scenes of every law (e.g. the tuned steps of ``ngdual bench``).
SOLVER_READS = {"auto": ("method", "metric", "max_iter"),
                "active-set": ("method", "metric", "max_iter"),
                "uzawa": tuple(f.name for f in dataclasses.fields(Solver))}


FRICTION_READS = {"none": ("law",), "tresca": ("law", "bound"),
                  "coulomb": ("law", "mu", "normal_stress")}


def given_keys(scene: Scene, section: str) -> set[str]:
    """The keys of ``section`` the user set: in the scene's document (TOML, overrides), or,
    for a scene built in Python, those that differ from the default."""
    obj, given = getattr(scene, section), scene.__dict__.get("_given", frozenset())
    default = type(obj)()
    return {f.name for f in dataclasses.fields(obj)
            if f"{section}.{f.name}" in given or getattr(obj, f.name) != getattr(default, f.name)}


def _settings_without_effect(scene: Scene) -> list[tuple[str, str]]:
    """``(field, message)`` for every setting the chosen method or friction law ignores.

    A setting that does nothing is an error, not a silence: ``solver.rho`` with the
    active-set solver, ``friction.mu`` without Coulomb friction, ...
    """
    found = []
    method = scene.solver.method
    for key in sorted(given_keys(scene, "solver") - set(SOLVER_READS[method])):
        found.append((f"solver.{key}", f"does nothing with solver.method = {method!r}: the "
                      "active-set solver iterates to round-off and reads only metric and "
                      "max_iter; remove it, or set solver.method = \"uzawa\" for the "
                      "thesis' Algorithms 3.38 / 3.41"))
    law = scene.friction.law if scene.friction.law in FRICTION_LAWS else "none"
    users = {"mu": "coulomb", "normal_stress": "coulomb", "bound": "tresca"}
    for key in sorted(given_keys(scene, "friction") - set(FRICTION_READS[law])):
        found.append((f"friction.{key}", f"does nothing with friction.law = {law!r}: only "
                      f"{users[key]!r} friction uses it; remove it, or set friction.law = "
                      f"\"{users[key]}\""))
    return found
