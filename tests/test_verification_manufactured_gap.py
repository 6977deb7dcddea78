"""The manufactured frictionless contact case with a gap that P_2 represents on the contact zone.

The facet multipliers see the gap through its P_k interpolant on every fine edge; on the
contact zone that interpolant is the prescribed normal displacement, and at k = 2 its
error against the P_2 projection is an odd saw of amplitude h^3 on every edge, which costs
half an order (docs/theory/order.md, "What limits k = 2: the interpolated gap").
``frictionless_case(a, gap="quadratic")`` takes u_n = g quadratic on the contact zone, so
the interpolant is exact there and what remains is the method alone: sigma, u, the rotation
and the pressure at order k + 1 = 3, the contact set exact.
"""

import numpy as np
import pytest

from ngdual.verification.manufactured import APPROACH, Y0, frictionless_case
from ngdual.verification.order import ORDER_SLACK, contact_study

pytestmark = pytest.mark.filterwarnings("ignore::ngdual.solution.PhysicsWarning")


def test_the_quadratic_gap_is_a_p2_function_on_the_contact_zone_and_the_quartic_is_not():
    x = np.linspace(-1.95, 1.95, 40)     # inside the contact zone, off its ends
    quadratic, quartic = (frictionless_case(2.0, gap=gap).exact.gap for gap in
                          ("quadratic", "quartic"))
    assert np.allclose(quadratic.numpy(x, Y0), APPROACH * (1 - x * x / 16), atol=1e-15)
    assert np.allclose(quadratic.dx().dx().dx().numpy(x, Y0), 0.0, atol=1e-15)
    # APPROACH (1 - x^2/16)^2 has the third derivative APPROACH 3 x / 32, which the P_2
    # interpolant misses
    assert np.allclose(quartic.dx().dx().dx().numpy(x, Y0), APPROACH * 3 * x / 32)


def test_the_quadratic_gap_is_a_named_variant_and_an_unknown_gap_is_refused():
    assert frictionless_case(2.0, gap="quadratic").name == "frictionless-a2-gap-quadratic"
    assert frictionless_case(2.0).name == "frictionless-a2"
    with pytest.raises(ValueError, match="gap"):
        frictionless_case(2.0, gap="cubic")


def test_at_order_2_a_gap_that_p2_represents_on_the_contact_zone_converges_at_order_3():
    """Levels 1-3 (measured: sigma 3.14, 3.08; pressure 3.08, 3.05; levels 4, 5: 3.05,
    3.02 and 3.03, 3.01; with the quartic u_n sigma falls to 2.68 and the pressure to
    2.08 on level 5)."""
    rows = contact_study(2, (1, 2, 3), gap="quadratic")
    assert all(row["contact_set"] == 0.0 for row in rows)
    for quantity in ("sigma", "pressure"):
        rates = [row[quantity + "_order"] for row in rows[1:]]
        assert all(abs(r - 3) <= ORDER_SLACK for r in rates), (quantity, rates)
