"""Table 4.3: norms per step of the adaptive algorithm with fraction marking (theta = 0.2),
mu_f = 0.5."""

from ngdual.studies.figures import adaptive_task, markdown_table, require, script_main
from ngdual.studies.figures.kit import NORM_KEYS, NORM_LABELS

THESIS = "Table 4.3"
STUDIES = ("adaptive",)


def run(ctx):
    # COMPUTE: the adaptive run (shared with Figs. 4.9-4.13)
    task = adaptive_task(ctx.plan, "coulomb", "fraction")
    history = require(ctx.record(task), task.label)["history"]
    rows = [{"step": r["step"], **{k: r["norms"][k] for k in NORM_KEYS},
             "dofs": r["dofs"]["total"]} for r in history]
    # WRITE
    data = ctx.write_csv("tab_4_3_norms_fraction_marking.csv", rows,
                         "norms per adaptive step, fraction marking theta = 0.2, mu_f = 0.5")
    ctx.entry(THESIS, "Norms, fraction marking", [data],
              {"steps": len(rows), "DOFs first / last": [rows[0]["dofs"], rows[-1]["dofs"]]},
              table=markdown_table(rows, {"step": "step", **{k: NORM_LABELS[k]
                                                              for k in NORM_KEYS[:-1]}}))


if __name__ == "__main__":
    script_main(__file__)
