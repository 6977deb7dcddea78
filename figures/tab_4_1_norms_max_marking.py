"""Table 4.1: norms and DOFs per step of the adaptive algorithm with max marking (theta = 0.5),
mu_f = 0.5; compare with the uniform levels of Table 3.2."""

from ngdual.studies.figures import adaptive_task, markdown_table, require, script_main
from ngdual.studies.figures.kit import NORM_KEYS, NORM_LABELS

THESIS = "Table 4.1"
STUDIES = ("adaptive",)


def run(ctx):
    # COMPUTE: the adaptive run (shared with Figs. 4.1-4.8)
    task = adaptive_task(ctx.plan, "coulomb", "max")
    history = require(ctx.record(task), task.label)["history"]
    rows = [{"step": r["step"], **{k: r["norms"][k] for k in NORM_KEYS},
             "dofs": r["dofs"]["total"], "elements": r["elements"]} for r in history]
    # WRITE
    data = ctx.write_csv("tab_4_1_norms_max_marking.csv", rows,
                         "norms and DOFs per adaptive step, max marking theta = 0.5, mu_f = 0.5")
    ctx.entry(THESIS, "Norms and DOFs, max marking", [data],
              {"steps": len(rows), "DOFs first / last": [rows[0]["dofs"], rows[-1]["dofs"]]},
              table=markdown_table(rows, {"step": "step", **{k: NORM_LABELS[k]
                                                              for k in NORM_KEYS[:-1]},
                                          "dofs": "Dof"}),
              thesis_says="still close to the pre-asymptotic range for sigma after 28 steps.")


if __name__ == "__main__":
    script_main(__file__)
