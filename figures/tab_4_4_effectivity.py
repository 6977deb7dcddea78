"""Table 4.4: total error e_tot (3.124), DOFs and effectivity eta_tot / e_tot per step of fraction
marking (theta = 0.2), mu_f = 0.5.

eta_tot = sum_T eta_{tot,T} as in the thesis (also given: (sum_T eta_{tot,T}^2)^(1/2));
e_tot against the Aitken limits of the uniform levels (Table 3.2), so it is meaningful only
while it is well above the error of that reference (about the error of level K).
"""

from ngdual.studies.figures import adaptive_task, errors, markdown_table, require, script_main
from ngdual.studies.sweep import estimator

THESIS = "Table 4.4"
STUDIES = ("adaptive", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the adaptive run and the reference norms of the uniform levels
    task = adaptive_task(ctx.plan, "coulomb", "fraction")
    history = require(ctx.record(task), task.label)["history"]
    errs = errors(history, ctx.reference("coulomb"))
    rows = []
    for r, e in zip(history, errs):
        e_tot = e["e_tot"] if e else None
        rows.append({"step": r["step"], "e_tot": e_tot, "dofs": r["dofs"]["total"],
                     "eta_sum": estimator(r, "sum"), "eta": estimator(r),
                     "effectivity": estimator(r, "sum") / e_tot if e_tot else None,
                     "effectivity_l2": estimator(r) / e_tot if e_tot else None})
    # WRITE
    data = ctx.write_csv("tab_4_4_effectivity.csv", rows,
                         "e_tot, DOFs and effectivity per step, fraction marking theta = 0.2")
    ctx.entry(THESIS, "Total error, DOFs and effectivity index", [data],
              {"effectivity eta_tot / e_tot range": [min(r["effectivity"] for r in rows
                                                         if r["effectivity"]),
                                                     max(r["effectivity"] for r in rows
                                                         if r["effectivity"])]},
              table=markdown_table(rows, {"step": "step", "e_tot": "e_tot", "dofs": "Dof",
                                          "effectivity": "eta_tot / e_tot",
                                          "effectivity_l2": "(sum eta^2)^1/2 / e_tot"}),
              thesis_says="the effectivity index is not satisfactory (growing eta_as^max).",
              notes=f"reference: Aitken limit of uniform levels {ctx.plan.reference_levels}")


if __name__ == "__main__":
    script_main(__file__)
