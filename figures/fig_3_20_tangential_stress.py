"""Fig. 3.20: tangential stress sigma_t^h on Gamma_C (constant per fine edge), both problems.

The thesis: zero without friction (free sliding); with friction the friction forces act
tangentially, with the sign of lambda_t.
"""

from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import gamma_c_stress

THESIS = "Fig. 3.20"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE, WRITE, PLOT: both problems on the field level (shared with Tables 3.2/3.3)
    files, numbers = gamma_c_stress(ctx, ctx.both_fields(), THESIS, "sigma_t", r"\sigma_t",
                                    "tangential stress", "fig_3_20_tangential_stress")
    ctx.entry(THESIS, "Tangential stress sigma_t on Gamma_C", files, numbers,
              thesis_says="sigma_t = 0 without friction; friction forces with friction.")


if __name__ == "__main__":
    script_main(__file__)
