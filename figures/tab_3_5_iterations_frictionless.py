"""Table 3.5: iterations and solution times of Algorithm 3.38 (no friction), default and best rho.

rho (dimensionless: the metric carries the plane-strain modulus) is searched on a grid on
every level; "optimal" is the fewest iterations (ties: the shorter iteration time). Times:
"solve" is the Uzawa iteration (after the one factorisation), "total" includes meshing,
assembly and factorisation. Sweep tasks run two at a time, so times carry that noise.
Last columns: the default active-set solver (semismooth Newton steps, no parameter).
"""

from ngdual.studies.figures import markdown_table, script_main
from ngdual.studies.figures.kit import rho_search, solver_columns

THESIS = "Table 3.5"
STUDIES = ("rho-frictionless", "uniform-frictionless")


def run(ctx):
    # COMPUTE: the rho grid on every level, against rho = 1 and the active-set solver
    rows = []
    for level, (at, opt, active_set) in rho_search(ctx, "frictionless").items():
        row = {"level": level, **solver_columns(at.get(1.0), {"it": "outer"})}
        if opt is not None:
            row.update(rho_opt=opt, **solver_columns(at[opt], {"it_opt": "outer"}, "_opt"))
        row.update(solver_columns(active_set, {"newton": "inner"}, "_fast"))
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
