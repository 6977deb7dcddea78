"""Table 3.1: degrees of freedom of every space and the mesh size h per level.

X: stress (RT_0 rows + curl bubbles), M: displacement (P0^2), S: rotation (P1), N: phi on the
h~ mesh of Gamma_N, C: lambda_n (and lambda_t) on the h~ mesh of Gamma_C, L: nu on the
h^ = 2h~ mesh. Counted without assembling; compared with the thesis numbers.
"""

from ngdual.studies.figures import markdown_table, script_main

THESIS = "Table 3.1"
STUDIES = ("dofs",)
THESIS_ROWS = {  # level: (h, X, M, S, N, C, L), Table 3.1
    1: (1.4142, 180, 64, 27, 6, 3, 2), 2: (0.7071, 680, 256, 85, 14, 7, 4),
    3: (0.3536, 2640, 1024, 297, 30, 15, 8), 4: (0.1768, 10400, 4096, 1105, 62, 31, 16),
    5: (0.0884, 41280, 16384, 4257, 126, 63, 32), 6: (0.0442, 164480, 65536, 16705, 254, 127, 64),
    7: (0.0221, 656640, 262144, 66177, 510, 255, 128),
    8: (0.0110, 2624000, 1048576, 263425, 1022, 511, 256)}
KEYS = ("X", "M", "S", "N", "C", "L")


def run(ctx):
    # COMPUTE: the spaces of every level (no assembly)
    records = ctx.compute(ctx.studies()["dofs"])
    rows = []
    for level, record in zip(ctx.plan.levels, records):
        thesis = THESIS_ROWS[level]
        rows.append({"level": level, "h": record["h"], **record["dofs"],
                     "total": record["ndof"],
                     "matches_thesis": all(record["dofs"][k] == v
                                           for k, v in zip(KEYS, thesis[1:])),
                     **{f"thesis_{k}": v for k, v in zip(("h", *KEYS), thesis)}})
    # WRITE
    data = ctx.write_csv("tab_3_1_dofs.csv", rows, "DOFs per space and mesh size per level, "
                         "ours and the thesis' (Table 3.1)")
    ctx.entry(THESIS, "Degrees of freedom and mesh sizes", [data],
              {"levels matching the thesis exactly": f"{sum(r['matches_thesis'] for r in rows)}"
                                                      f" of {len(rows)}"},
              table=markdown_table(rows, {"level": "level", "h": "h", "X": "Dof(X)",
                                          "M": "Dof(M)", "S": "Dof(S)", "N": "Dof(N)",
                                          "C": "Dof(C)", "L": "Dof(L)", "total": "total",
                                          "matches_thesis": "= thesis"}),
              thesis_says="the DOF counts above for levels 1-8 (h = sqrt(2) 2^(1-k)); h~ = "
                          "sqrt(2) h on the boundary (in our mesh the boundary edges have "
                          "length h / sqrt(2) and h~ = 2 of them).")


if __name__ == "__main__":
    script_main(__file__)
