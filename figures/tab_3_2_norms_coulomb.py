"""Table 3.2: norms of the solutions per level, Coulomb friction mu_f = 0.5 (Algorithm 3.41).

||sigma||_X in H(div), the others in L^2 (nu on A_C); last row: the Aitken Delta^2 limit of the
last three levels, the reference of the total error (3.124).
"""

from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import NORM_KEYS, norms_table

THESIS = "Table 3.2"
STUDIES = ("uniform-coulomb",)


def run(ctx):
    norms_table(ctx, THESIS, "coulomb", "tab_3_2_norms_coulomb", NORM_KEYS)


if __name__ == "__main__":
    script_main(__file__)
