"""Fig. 3.15: phi_1^h on Gamma_N, the horizontal component of the coarse h~ P1 multiplier
(phi = -u on Gamma_N), both problems."""

from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import neumann_multiplier

THESIS = "Fig. 3.15"
STUDIES = ("uniform-frictionless", "uniform-coulomb")


def run(ctx):
    # COMPUTE: the solves of both problems on the field level (shared with Tables 3.2/3.3)
    # WRITE, PLOT: the CSV, one panel per problem and the index entry
    neumann_multiplier(ctx, THESIS, 1, "fig_3_15_phi1")


if __name__ == "__main__":
    script_main(__file__)
