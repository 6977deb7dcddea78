"""Table 3.3: norms of the solutions per level without friction, mu_f = 0 (Algorithm 3.38).

||sigma||_X in H(div), the others in L^2; last row: the Aitken Delta^2 limit of the last three
levels, the reference of the total error (3.124).
"""

from ngdual.studies.figures import script_main
from ngdual.studies.figures.kit import NORM_KEYS, norms_table

THESIS = "Table 3.3"
STUDIES = ("uniform-frictionless",)


def run(ctx):
    norms_table(ctx, THESIS, "frictionless", "tab_3_3_norms_frictionless", NORM_KEYS[:-1])


if __name__ == "__main__":
    script_main(__file__)
