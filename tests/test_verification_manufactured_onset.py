"""The onset p of the manufactured frictionless case: the regularity it gives and the contact
set it lets the discrete problem recover.

``frictionless_case(a, onset=p)`` lets sigma_n and lambda_n grow like d^p from the ends
x = +-a of the contact set: their first p - 1 derivatives are continuous there and the p-th
jumps (sigma_n, lambda_n in H^{p+1/2-eps}(Gamma_C)), and sigma, which carries Y sigma_n'(x)
in sigma_12, jumps in its (p-1)-th x-derivative across the lines x = +-a (sigma in
H^{p-1/2-eps}(Omega)). The jumps are read off the exact piecewise polynomials.
"""

import math

import numpy as np
import pytest

from ngdual.verification.manufactured import (
    ONSET,
    PRESSURE,
    Y0,
    frictionless_case,
    manufactured_case,
)
from ngdual.verification.order import contact_study
from ngdual.verification.piecewise import Piecewise, poly_numpy

pytestmark = pytest.mark.filterwarnings("ignore::ngdual.solution.PhysicsWarning")


def _jumps(f: Piecewise, x0: float, y0: float, up_to: int) -> list[float]:
    """The jumps across x = x0 (a breakpoint of f) of f, f', ..., f^(up_to) at y = y0."""
    out = []
    for _ in range(up_to + 1):
        i = list(f.breaks).index(x0)
        out.append(float(poly_numpy(f.pieces[i + 1], x0, y0) - poly_numpy(f.pieces[i], x0, y0)))
        f = f.dx()
    return out


@pytest.mark.parametrize("onset", [2, 3, 4])
def test_sigma_n_and_lambda_n_are_c_p_minus_1_with_a_jump_of_the_p_th_derivative_at_the_ends(
        onset):
    case = frictionless_case(2.0, onset=onset)
    for x0 in (-2.0, 2.0):
        sigma_n = _jumps(case.sigma_n, x0, Y0, onset)
        lam_n = _jumps(case.lam_n, x0, Y0, onset)
        assert np.allclose(sigma_n[:onset], 0.0, atol=1e-9) and np.allclose(
            lam_n[:onset], 0.0, atol=1e-12)
        # -P (1 - x^2/4)^p = -P (d (4 - d) / 4)^p: the p-th derivative jumps by P p! at d = 0
        assert abs(sigma_n[onset]) == pytest.approx(PRESSURE * math.factorial(onset))
        assert abs(lam_n[onset]) > 0.0


@pytest.mark.parametrize("onset", [2, 3, 4])
def test_sigma_jumps_in_its_p_minus_1_th_derivative_across_the_lines_x_equal_pm_a(onset):
    sigma_12 = frictionless_case(2.0, onset=onset).exact.sigma[0][1]
    jumps = _jumps(sigma_12, 2.0, Y0 + 1.0, onset - 1)    # inside the body, Y = 1
    assert np.allclose(jumps[:onset - 1], 0.0, atol=1e-9) and abs(jumps[onset - 1]) > 1e-3


def test_the_default_onset_is_the_quadratic_one_of_the_named_cases():
    named, default = manufactured_case("frictionless"), frictionless_case(2.0)
    assert ONSET == 2 and named.sigma_n == default.sigma_n and named.lam_n == default.lam_n
    assert frictionless_case(2.0, onset=3).name == "frictionless-a2-onset3"


def test_an_onset_below_two_is_refused():
    with pytest.raises(ValueError, match="onset"):
        frictionless_case(2.0, onset=1)


@pytest.mark.parametrize("onset, missed", [(2, 0.0), (3, 0.5)])
def test_at_order_2_the_quadratic_onset_recovers_the_contact_set_and_the_cubic_misses_an_edge(
        onset, missed):
    """k = 2, level 3 (fine edges of length 1/4): a margin d^3 next to the ends falls below
    the errors of the Bernstein coefficients, and one fine edge at each end is decided wrong
    (measured on levels 3-5: 0.5, 0.25, 0.125; with d^2: 0 on levels 1-5)."""
    row, = contact_study(2, (3,), onset)
    assert row["contact_set"] == pytest.approx(missed, abs=1e-12)
