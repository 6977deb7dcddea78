"""Table 4.2: the largest asymmetry indicator eta_as^max with as(sigma_h) in L^2 and in H(div),
and the share q_as of triangles with eta_as,T >= 0.1 eta_as^max, per step of max marking."""

from ngdual.studies.figures import adaptive_task, markdown_table, require, script_main

THESIS = "Table 4.2"
STUDIES = ("adaptive",)


def run(ctx):
    # COMPUTE: the adaptive run (shared with Figs. 4.1-4.8)
    task = adaptive_task(ctx.plan, "coulomb", "max")
    history = require(ctx.record(task), task.label)["history"]
    rows = [{"step": r["step"], "max_l2": r["eta_as"]["l2"]["max"], "q_l2": r["eta_as"]["l2"]["q"],
             "max_hdiv": r["eta_as"]["hdiv"]["max"], "q_hdiv": r["eta_as"]["hdiv"]["q"],
             "elements": r["elements"]} for r in history]
    # WRITE
    data = ctx.write_csv("tab_4_2_asymmetry_indicator.csv", rows,
                         "eta_as^max (L2 and H(div)) and q_as per step, max marking")
    ctx.entry(THESIS, "Largest asymmetry indicator and the share near it", [data],
              {"eta_as^max L2 first / last": [rows[0]["max_l2"], rows[-1]["max_l2"]],
               "eta_as^max H(div) first / last": [rows[0]["max_hdiv"], rows[-1]["max_hdiv"]],
               "q_as (L2) first / last": [rows[0]["q_l2"], rows[-1]["q_l2"]]},
              table=markdown_table(rows, {"step": "step", "max_l2": "eta_as^max (L2)",
                                          "q_l2": "q_as", "max_hdiv": "eta_as^max (H(div))",
                                          "q_hdiv": "q_as"}),
              thesis_says="with H(div) eta_as^max grows as h decreases, with L2 it stays about "
                          "constant; q_as tends to zero; the maximum sits in the two lower "
                          "corners.")


if __name__ == "__main__":
    script_main(__file__)
