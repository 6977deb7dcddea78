"""Table 3.4: total error e_tot (3.124) and rate alpha per level, mu_f = 0 and mu_f = 0.5.

e_i(q) = | ||q_i||^2 - n_q^2 |^(1/2), n_q the Aitken limit of the last three levels (Tables
3.2/3.3); alpha = -2 log(e_i / e_{i+1}) / log(N_i / N_{i+1}) (:mod:`ngdual.rates`). The last
level's error is measured against a limit computed from it (and equals 0 in a norm whose
increments do not shrink yet: Aitken's safeguard then returns the last value), so it is
biased low and its alpha is left out, as is the last level from the least-squares rate.
"""

from ngdual.rates import fitted_rate, observed_rates
from ngdual.studies.figures import PROBLEM_TITLES, errors, markdown_table, script_main

THESIS = "Table 3.4"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: errors against the Aitken limits, rates between levels
    rows, numbers = [], {}
    for problem in ("frictionless", "coulomb"):
        records = ctx.uniform(problem)
        errs = errors(records, ctx.reference(problem))
        ndofs = [r["ndof"] if r else None for r in records]
        e_tot = [e["e_tot"] if e else None for e in errs]
        # level K is part of its own reference: no rate into it
        alphas = observed_rates(ndofs, e_tot)[:-1] + [None]
        for level, n, e, a, err in zip(ctx.plan.levels, ndofs, e_tot, alphas, errs):
            rows.append({"problem": problem, "level": level, "ndof": n, "e_tot": e,
                         "alpha": a, **{f"e_{q}": v for q, v in (err or {}).get(
                             "errors", {}).items()}})
        ok = [(n, e) for n, e in zip(ndofs[:-1], e_tot[:-1]) if n and e]
        if len(ok) >= 2:
            fit = fitted_rate(*zip(*ok[-3:]))
            numbers[f"alpha (least squares, last 3 levels before K), {PROBLEM_TITLES[problem]}"
                    ] = fit
    # WRITE
    data = ctx.write_csv("tab_3_4_total_error.csv", rows,
                         "total error (3.124) and rate alpha per level, both problems")
    wide = []
    for level in ctx.plan.levels:
        f, c = ({r["problem"]: r for r in rows if r["level"] == level}[p]
                for p in ("frictionless", "coulomb"))
        wide.append({"level": level, "n0": f["ndof"], "e0": f["e_tot"], "a0": f["alpha"],
                     "n1": c["ndof"], "e1": c["e_tot"], "a1": c["alpha"]})
    ctx.entry(THESIS, "Total error and rate of convergence", [data], numbers,
              table=markdown_table(wide, {"level": "level", "n0": "Dof (mu_f = 0)",
                                          "e0": "e_tot", "a0": "alpha",
                                          "n1": "Dof (mu_f = 0.5)", "e1": "e_tot",
                                          "a1": "alpha"}),
              thesis_says="alpha about 0.45 (slope -1/5 in Fig. 3.22, 'alpha = 1/sqrt(5)').")


if __name__ == "__main__":
    script_main(__file__)
