"""The primal peer (:mod:`ngdual.studies.primal_peer`) against the half-plane solutions
(``ngdual bench primal-peer``): Hertz (frictionless) and Cattaneo-Mindlin (Coulomb or
Tresca friction), P1 and P2, on locally refined levels, for every Nitsche variant theta
and penalty gamma0 asked for (the gamma study: which gamma0 keeps Newton converging).
"""

from __future__ import annotations

from dataclasses import fields

from .measure import header

CASES = ("hertz", "cattaneo-mindlin")
# the tables ngdual bench primal-peer prints: (title, key of a record, format)
_FIRST = (("theta", "theta", "5.1f"), ("gamma0", "gamma0", "6.1f"), ("P", "order", "2d"),
          ("lvl", "level", "3d"), ("h_C", "hc", "8.5f"), ("ndof", "ndof", "7d"),
          ("it", "newton_iterations", "3d"), ("time/s", "time_total", "7.2f"))
COLUMNS = {
    "hertz": (*_FIRST, ("asm/s", "time_assemble", "6.2f"), ("sol/s", "time_solve", "6.2f"),
              ("L2 rel", "l2_error", "9.2e"), ("max rel", "max_error", "9.2e"),
              ("a_Hertz", "a_hertz", "8.5f"), ("a_h", "a_measured", "8.5f"),
              ("P", "force", "9.6f"), ("reaction", "reaction", "9.6f"),
              ("uy/McEwen", "approach_ratio", "9.4f")),
    "cattaneo-mindlin": (*_FIRST, ("P", "P", "9.5f"), ("Q", "Q", "10.6f"),
                         ("a", "a_hertz", "8.5f"), ("c formula", "c_formula", "9.5f"),
                         ("c_h", "c_measured", "8.5f"), ("|dc|/h_C", "stick_error_per_hc", "8.2f"),
                         ("q L2 rel", "traction_l2_error", "9.2e")),
}


def one_case(case: str, order: int, level: int, hc: float, theta: float, gamma0: float,
             **physics) -> dict:
    """One solve of ``case`` (:data:`CASES`) by the primal peer: its row as a record, or the
    Newton failure as ``error``. ``physics``: ``nu`` and (Cattaneo-Mindlin) ``law``."""
    from ..primal_peer import NewtonError, cattaneo_mindlin_case, hertz_case

    settings = {"case": case, "order": order, "level": level, "theta": theta,
                "gamma0": gamma0, **physics}
    solve = hertz_case if case == "hertz" else cattaneo_mindlin_case
    try:
        row = solve(order, level, mesh_kw={"hc": hc}, theta=theta, gamma0=gamma0, **physics)
    except NewtonError as err:
        return {**settings, "hc": hc, "converged": False, "error": str(err)}
    record = {**settings, **{f.name: getattr(row, f.name) for f in fields(row)
                             if f.name != "result"}, "converged": True, "error": None}
    if case == "cattaneo-mindlin":
        record["stick_error_per_hc"] = abs(row.c_measured - row.c_formula) / row.hc
    return record


def run(case: str = "hertz", orders=(1, 2), levels=(1, 2, 3, 4, 5), hc: float = 0.05,
        thetas=(-1.0,), gammas=(1.0,), on_record=None, **physics) -> dict:
    """Every (theta, gamma0, order, level) of ``case``; ``hc`` the contact edge length on
    level 1; ``on_record(study)`` after each record."""
    if case not in CASES:
        raise ValueError(f"unknown case {case!r}; use one of {CASES}")
    study = header("primal-peer", case=case, hc=hc, **physics)
    for theta in thetas:
        for gamma0 in gammas:
            for order in orders:
                for level in levels:
                    study["records"].append(one_case(case, order, level, hc, theta, gamma0,
                                                     **physics))
                    if on_record:
                        on_record(study)
    return study
