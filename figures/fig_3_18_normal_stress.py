"""Fig. 3.18: normal stress sigma_n^h on Gamma_C (constant per fine edge), both problems.

Also F_abs = int_{A_C} |sigma_n| + |sigma_t| ds (the total force on the active part).
The thesis: max |sigma_n| is larger without friction, although the contact zone is larger
with friction (kinks where the body changes between slip and stick); F_abs is larger with
friction.
"""

from ngdual.studies.figures import PROBLEM_TITLES, script_main
from ngdual.studies.figures.kit import gamma_c_stress

THESIS = "Fig. 3.18"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    fields = ctx.both_fields()
    # WRITE, PLOT: the CSV and one panel per problem
    files, numbers = gamma_c_stress(ctx, fields, THESIS, "sigma_n", r"\sigma_n", "normal stress",
                                    "fig_3_18_normal_stress")
    for p, (record, _) in fields.items():
        numbers[f"F_abs, {PROBLEM_TITLES[p]}"] = record["contact"]["F_abs"]
    ctx.entry(THESIS, "Normal stress sigma_n on Gamma_C", files, numbers,
              thesis_says="max |sigma_n| larger without friction; F_abs larger with friction "
                          "(the values are withheld in our copy of the thesis).")


if __name__ == "__main__":
    script_main(__file__)
