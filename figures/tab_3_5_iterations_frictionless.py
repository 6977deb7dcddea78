"""Table 3.5: iterations and solution times of Algorithm 3.38 (no friction), default and best rho.

rho (dimensionless: the metric carries the plane-strain modulus) is searched on a grid on
every level; "optimal" is the fewest iterations (ties: the shorter iteration time). Times:
"solve" is the Uzawa iteration (after the one factorisation), "total" includes meshing,
assembly and factorisation. Sweep tasks run two at a time, so times carry that noise.
Last columns: the default active-set solver (semismooth Newton steps, no parameter).
"""

from ngdual.studies.figures import best, markdown_table, rho_tasks, script_main, solve

THESIS = "Table 3.5"
STUDIES = ("rho-frictionless", "uniform-frictionless")


def run(ctx):
    # COMPUTE: the rho grid on every level
    tasks = rho_tasks(ctx.plan)["frictionless"]
    records = dict(zip(tasks, ctx.compute(list(tasks.values()))))
    rows = []
    for level in ctx.plan.levels:
        at = {rho: records[(lv, rho)] for lv, rho in tasks if lv == level}
        default, opt = at.get(1.0), best(at)
        row = {"level": level}
        if default and default["status"] == "ok":
            row.update(it=default["iterations"]["outer"], time=default["timings_s"]["solve"],
                       total=default["timings_s"]["total"])
        if opt is not None:
            r = at[opt]
            row.update(rho_opt=opt, it_opt=r["iterations"]["outer"],
                       time_opt=r["timings_s"]["solve"], total_opt=r["timings_s"]["total"])
        fast = ctx.record(solve(ctx.plan, "frictionless", level))
        if fast and fast["status"] == "ok":
            row.update(newton=fast["iterations"]["inner"], time_fast=fast["timings_s"]["solve"],
                       total_fast=fast["timings_s"]["total"])
        row["grid"] = {str(rho): (r["iterations"]["outer"] if r and r["status"] == "ok"
                                  else (r or {}).get("status", "missing"))
                       for rho, r in at.items()}
        rows.append(row)
    # WRITE
    data = ctx.write_json("tab_3_5_iterations_frictionless.json", {"rows": rows},
                          "Uzawa iterations and times per level: rho = 1 and the best rho of "
                          f"the grid {list(ctx.plan.rho_grid)}")
    csv = ctx.write_csv("tab_3_5_iterations_frictionless.csv",
                        [{k: v for k, v in r.items() if k != "grid"} for r in rows],
                        "Uzawa iterations and times per level (rho = 1 and optimal rho)")
    ctx.entry(THESIS, "Iterations and solution times without friction", [csv, data],
              {"rho_opt per level": [r.get("rho_opt") for r in rows]},
              table=markdown_table(rows, {"level": "It.", "it": "#It (rho = 1)",
                                          "time": "sol. time [s]", "rho_opt": "rho_opt",
                                          "it_opt": "#It", "time_opt": "sol. time [s]",
                                          "newton": "active set: steps",
                                          "time_fast": "sol. time [s]"}),
              thesis_says="with the optimal rho the solution time is halved on average.")


if __name__ == "__main__":
    script_main(__file__)
