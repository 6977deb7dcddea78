"""Analytic contact solutions: Hertz, the rigid flat punch, a blunt wedge, Cattaneo-Mindlin.

The half-plane solutions of plane-strain contact (Johnson, *Contact Mechanics*, 1985,
Sections 2.8, 5.2, 7.1), P and Q forces per unit thickness, E* = E / (1 - nu^2):

* Hertz (a cylinder of radius R on a rigid plane): a = sqrt(4 P R / (pi E*)),
  p(x) = p0 sqrt(1 - x^2/a^2), p0 = 2 P / (pi a).
* A blunt wedge (flanks of slope s = cot of the semi-angle) on a rigid plane:
  p(x) = (E* s / pi) arccosh(a / |x|), a = P / (E* s) (log-singular at the apex, in L2).
* Rigid flat punch of half-width a (Sadowsky): p(x) = P / (pi sqrt(a^2 - x^2)), singular
  at x = +-a; the force on |x| < a/2 is (2/pi) arcsin(1/2) P = P/3.
* Cattaneo-Mindlin (Hertz plus a tangential force |Q| < mu_f P, material with
  Dundurs' beta = 0, here nu -> 1/2 against a rigid plane): stick for |x| < c,
  c / a = sqrt(1 - |Q| / (mu_f P)), q(x) = mu_f p0 [sqrt(1 - x^2/a^2) - (c/a)
  sqrt(1 - x^2/c^2)_+] in the direction of Q.

The discrete pressure and shear traction compared with them, and their errors, are in
:mod:`ngdual.verification.traction`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# --- exact solutions ---------------------------------------------------------------------------

def _ellipse(x: np.ndarray, peak: float, half_width: float) -> np.ndarray:
    """peak * sqrt(1 - x^2 / half_width^2) inside, 0 outside."""
    x = np.asarray(x, dtype=float)
    if half_width <= 0:
        return np.zeros_like(x)
    return peak * np.sqrt(np.clip(1.0 - (x / half_width) ** 2, 0.0, None))


class _ContactZone:
    """A contact zone |x| < a (attribute ``a``): the pressure is smooth inside and has its
    break points at the ends only."""

    @property
    def breaks(self) -> tuple[float, ...]:
        return (-self.a, self.a)


@dataclass(frozen=True)
class HertzContact(_ContactZone):
    """Hertz contact of a cylinder (radius R) on a rigid plane, plane strain.

    >>> h = hertz(P=2.0, R=10.0, E=1.0, nu=0.0)
    >>> round(h.a, 6), round(float(h.pressure(np.array([0.0]))[0]) * math.pi * h.a / 2, 6)
    (5.046265, 2.0)
    """

    P: float
    R: float
    E_star: float
    a: float
    p0: float

    singular = False

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """p(x) = p0 sqrt(1 - x^2/a^2) on |x| < a, 0 outside."""
        return _ellipse(x, self.p0, self.a)


def hertz(P: float, R: float, E: float, nu: float) -> HertzContact:
    """Hertz: E* = E/(1 - nu^2), a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a) (P per unit
    thickness, Johnson 1985, eq. 5.40)."""
    e_star = E / (1.0 - nu * nu)
    a = math.sqrt(4.0 * P * R / (math.pi * e_star))
    return HertzContact(P, R, e_star, a, 2.0 * P / (math.pi * a))


def mcewen_approach(d: float, P: float, a: float, E: float, nu: float) -> float:
    """u_y(0, -d) - u_y(0, 0) below a Hertz contact on the half-plane (plane strain).

    Integrates eps_zz = (1 + nu)/E ((1 - nu) sigma_zz - nu sigma_xx) along the axis with
    McEwen's stresses sigma_zz = -p0 a / sqrt(a^2 + z^2),
    sigma_xx = -p0 ((a^2 + 2 z^2) / sqrt(a^2 + z^2) - 2 z) / a (Johnson, Contact Mechanics,
    Sec. 4.2), p0 = 2P / (pi a).
    """
    p0 = 2 * P / (math.pi * a)
    return (1 + nu) / E * p0 * ((1 - nu) * a * math.asinh(d / a)
                                - nu * (d * math.sqrt(a * a + d * d) - d * d) / a)


@dataclass(frozen=True)
class FlatPunch(_ContactZone):
    """A rigid flat punch of half-width a pressed with force P into a half-plane.

    >>> round(FlatPunch(3.0, 1.0).force_within(0.5), 12)
    1.0
    """

    P: float
    a: float

    singular = True

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """p(x) = P / (pi sqrt(a^2 - x^2)) on |x| < a, 0 outside (inf at x = +-a)."""
        x = np.asarray(x, dtype=float)
        inside = np.abs(x) < self.a
        out = np.zeros_like(x)
        out[inside] = self.P / (math.pi * np.sqrt(self.a**2 - x[inside] ** 2))
        return out

    def force_within(self, b: float) -> float:
        """int_{|x| < b} p = (2/pi) arcsin(b/a) P (P/3 for b = a/2)."""
        return 2.0 / math.pi * math.asin(min(b / self.a, 1.0)) * self.P


def flat_punch(P: float, a: float) -> FlatPunch:
    """The rigid flat punch (Sadowsky 1928; Johnson 1985, eq. 2.64)."""
    return FlatPunch(P, a)


@dataclass(frozen=True)
class Wedge:
    """A blunt elastic wedge with flanks of slope s pressed with force P on a rigid plane.

    >>> w = wedge(P=2.0, slope=0.1, E=1.0, nu=0.0)
    >>> round(w.a, 12), float(w.pressure(np.array([w.a, 2 * w.a]))[1])
    (20.0, 0.0)
    """

    P: float
    slope: float
    E_star: float

    singular = False   # log-singular at the apex, but in L2

    @property
    def a(self) -> float:
        """a = P / (E* s): with P = (E*/2) int x h'(x) / sqrt(a^2 - x^2) dx, h = s |x|."""
        return self.P / (self.E_star * self.slope)

    @property
    def breaks(self) -> tuple[float, ...]:
        return (-self.a, 0.0, self.a)

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """p(x) = (E* s / pi) arccosh(a / |x|) on |x| < a (inf at the apex), 0 outside."""
        x = np.abs(np.asarray(x, dtype=float))
        out = np.zeros_like(x)
        inside = x < self.a
        with np.errstate(divide="ignore"):
            out[inside] = self.E_star * self.slope / math.pi * np.arccosh(self.a / x[inside])
        return out


def wedge(P: float, slope: float, E: float, nu: float) -> Wedge:
    """The blunt wedge (Johnson 1985, Sec. 5.2), plane strain E* = E / (1 - nu^2)."""
    return Wedge(P, slope, E / (1.0 - nu * nu))


@dataclass(frozen=True)
class CattaneoMindlin:
    """Hertz contact plus a tangential force Q below sliding: stick for |x| < c.

    ``shear`` has the sign of Q and integrates to Q; ``pressure`` is the Hertz pressure.

    >>> cm = cattaneo_mindlin(P=1.0, Q=0.15, R=1.0, E=1.0, nu=0.5, mu_f=0.3)
    >>> round(cm.c / cm.hertz.a, 12)
    0.707106781187
    """

    hertz: HertzContact
    Q: float
    mu_f: float
    c: float

    singular = False

    @property
    def breaks(self) -> tuple[float, ...]:
        return (-self.hertz.a, -self.c, self.c, self.hertz.a)

    def pressure(self, x: np.ndarray) -> np.ndarray:
        return self.hertz.pressure(x)

    def shear(self, x: np.ndarray) -> np.ndarray:
        """q(x) = sign(Q) mu_f p0 [sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2)_+]."""
        h = self.hertz
        return math.copysign(1.0, self.Q) * self.mu_f * (
            _ellipse(x, h.p0, h.a) - _ellipse(x, h.p0 * self.c / h.a, self.c))


def cattaneo_mindlin(P: float, Q: float, R: float, E: float, nu: float,
                     mu_f: float) -> CattaneoMindlin:
    """Cattaneo (1938), Mindlin (1949): c = a sqrt(1 - |Q| / (mu_f P)) (Johnson 1985, 7.1)."""
    h = hertz(P, R, E, nu)
    return CattaneoMindlin(h, Q, mu_f, h.a * math.sqrt(max(0.0, 1.0 - abs(Q) / (mu_f * P))))
