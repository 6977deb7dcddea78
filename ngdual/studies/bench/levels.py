"""One scene on a sequence of uniform levels (``ngdual bench levels``): unknowns, outer and
inner iterations, the solver's times (assembly, factorisation, condensation, iterations),
peak memory and the norms of Tables 3.2/3.3 per level.

Each level runs in its own process, so that the peak memory is that of the level.
"""

from __future__ import annotations

from .measure import header, in_fresh_process, peak_rss_mb, solve_quietly, warning_messages

# the table ngdual bench levels prints: (title, key of a record, format)
COLUMNS = (("lvl", "level", "3d"), ("unknowns", "ndof", "9d"),
           ("outer", "iterations.outer", "6d"), ("inner", "iterations.inner", "6d"),
           ("assemble", "timings_s.assemble", "9.2f"), ("factor", "timings_s.factorize", "8.2f"),
           ("condense", "timings_s.condense", "8.2f"), ("iterate", "timings_s.solve", "8.2f"),
           ("total", "timings_s.total", "8.2f"), ("RSS MB", "peak_rss_mb", "7.0f"),
           ("sigma_X", "norms.sigma_X", "12.6e"), ("u", "norms.u", "11.5e"),
           ("eta", "norms.eta", "11.5e"), ("phi", "norms.phi", "11.5e"),
           ("lam_t", "norms.lam_t", "11.5e"), ("lam_n", "norms.lam_n", "11.5e"))


def one_level(scene: str, level: int, overrides: list[str]) -> dict:
    """Solve ``scene`` (name or path, with ``overrides``) on ``level``: its record."""
    from ...io import versions
    from ...quantities import norms
    from ...scene import load_scene

    solution = solve_quietly(load_scene(scene, overrides), level)
    return {"scene": scene, "level": level, "overrides": overrides,
            "ndof": solution.problem.n, "dofs": solution.problem.spaces.dofs(),
            "converged": solution.converged, "iterations": solution.iterations,
            "timings_s": solution.timings, "norms": norms(solution),
            "peak_rss_mb": peak_rss_mb(), "warnings": warning_messages(solution),
            "versions": versions()}


def run(scene: str, levels, overrides=(), on_record=None) -> dict:
    """The records of ``scene`` on every level of ``levels``, each in a fresh process;
    ``on_record(study)`` after each record with everything so far."""
    study = header("levels", scene=scene, overrides=list(overrides))
    for level in levels:
        study["records"].append(in_fresh_process("levels:one_level", scene=scene, level=level,
                                                 overrides=list(overrides)))
        if on_record:
            on_record(study)
    return study
