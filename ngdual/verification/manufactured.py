"""Manufactured contact solutions with known contact, stick and slip sets (their errors:
:mod:`ngdual.verification.manufactured_errors`).

The body is the rectangle of Example 3.46, Omega = (-4, 4) x (-1, 1) with its structured
mesh (levels 1, 2, ...: h~ = 2h = 2^(2-k) on Gamma_C), clamped sides Gamma_D = {x = +-4}
carrying the exact displacement, Gamma_N = top with the exact traction, and
Gamma_C = bottom (y = -1, outward normal n = (0, -1), t = (n_2, -n_1) = (-1, 0)).
On Gamma_C ngdual's conventions (:mod:`ngdual.forms`, Theorem 3.10) give

    sigma_n = sigma_22,   sigma_t = t . sigma n = sigma_12,
    lambda_n = g - u_n = g + u_2,   lambda_t = -u_t = u_1,

and from (3.62)_5,7 sigma_t = F nu with nu = sign(lambda_t) where lambda_t != 0: a slipping
point moves against its tangential traction, sigma_t u_t + F |u_t| = 0 as in (3.1).

The displacement is built from its traces. Given on Gamma_C (functions of x, Y = y + 1)
the tangential multiplier lambda_t, the normal displacement u_n, the normal and tangential
stresses sigma_n, sigma_t and interior terms c_1, c_2,

    u_1 = lambda_t + Y b_1 + Y^2 c_1,    u_2 = -u_n + Y b_2 + Y^2 c_2,
    b_1 = sigma_t / mu + u_n',           b_2 = (sigma_n - lam lambda_t') / (lam + 2 mu),

so that u = (lambda_t, -u_n), sigma_12 = sigma_t and sigma_22 = sigma_n on Y = 0. The gap is
g = u_n + lambda_n with the chosen lambda_n >= 0, f = -div sigma, t0 = sigma n on the top and
u_D = u on the sides.

The traces are piecewise polynomials in x with breakpoints at the end points of the contact,
stick and slip sets. There sigma_n, lambda_n and the friction margin F - |sigma_t| start
like (.)_+^2 (C^1 functions) and lambda_t, whose derivative enters b_2, like (.)_+^3 (C^2).
So u is C^1 with piecewise polynomial second derivatives: u in H^{5/2-eps}, sigma in
H^{3/2-eps} (in H^1), lambda_t, lambda_n in H^{5/2-eps}(Gamma_C), and div sigma = -f is
piecewise polynomial with jumps across the lines x = const through the set end points.
:func:`frictionless_case` takes the onset p as a parameter and states what each p gives.

Why quadratic onsets and a small lift. The discrete sets are decided node by node against
the exact margins next to a set end point -- the pressure, the gap lambda_n, F - |sigma_t| at
distance ~h~ -- and these must dominate the O(h^2) nodal errors. A d^2 margin scales like
them, so only a bounded number of nodes can be misclassified; a d^3 margin (the smoothest
choice, sigma in H^2) falls below them as h -> 0. The gap opens with a small coefficient
(``LIFT``) because the P1 multiplier lambda_n^h has a kink at the last contact node, which
the discrete solution pays for with a concentrated normal force proportional to the
opening (see :func:`contact_profile`); with a 5x larger ``LIFT`` that force separates the
node before it on level 6.

Every case presses the middle of Gamma_C into contact and lifts off towards the clamped
ends: the exact lambda_n and lambda_t vanish at the ends of Gamma_C, whatever values the
discrete multipliers take there (zero in C_h~ of (3.61), or the data's values).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

from ..scene import (
    Contact,
    Discretisation,
    Friction,
    Geometry,
    Loads,
    Material,
    Scene,
    Solver,
    validate,
)
from .piecewise import Piecewise

Y0 = -1.0                       # Gamma_C is the side y = Y0
HALF_WIDTH = 4.0                # Gamma_C = (-4, 4) x {Y0}
E, NU = 1000.0, 0.3
PRESSURE = 5.0                  # peak contact pressure |sigma_n|
LIFT = 0.002                    # peak of lambda_n on the separated parts (see contact_profile)
SLIDE = 0.005                   # scale of lambda_t = u_1 on Gamma_C
APPROACH = 0.01                 # u_n = APPROACH (1 - x^2/16)^2 on Gamma_C (quartic)
GAPS = ("quartic", "quadratic")  # the normal displacement u_n of frictionless_case
ONSET = 2                       # sigma_n, lambda_n, F - |sigma_t| grow like d^ONSET from a set
                                # end point, lambda_t like d^(ONSET + 1) (lambda_t' enters u_2)
QUANTITIES = ("sigma", "sigma_hdiv", "u", "eta", "lam_n", "lam_t")
SETS = ("contact_set", "stick_set")


# --- building blocks on Gamma_C ----------------------------------------------------------------

def _x() -> Piecewise:
    return Piecewise.x()


def cap(a: float, k: int = ONSET) -> Piecewise:
    """(1 - x^2/a^2)_+^k: one on x = 0, zero outside (-a, a)."""
    return Piecewise.window(-a, a, (1.0 - _x() * _x() / (a * a)) ** k)


def bump(left: float, right: float, k: int = ONSET) -> Piecewise:
    """((x - left)(right - x) / ((right - left)/2)^2)_+^k: one at the middle of (left, right)."""
    half = 0.5 * (right - left)
    inside = ((_x() - left) * (right - _x()) / (half * half)) ** k
    return Piecewise.window(left, right, inside)


def smooth_sign(b: float) -> Piecewise:
    """sign(x) for |x| >= b, the odd C^1 smoothstep p(x/b) inside.

    p(z) = z (3 - z^2) / 2: p(1) = 1, p'(1) = 0, and 1 - |p| = (1 - |z|)^2 (2 + |z|) / 2 > 0
    for |z| < 1, a quadratic margin at the end of the stick zone.
    """
    z = _x() / b
    p = z * (3.0 - z * z) / 2.0
    return Piecewise((-b, b), ({(0, 0): -1.0}, p.pieces[0], {(0, 0): 1.0}))


def stick_towards_ends(b: float, d: float, k: int = ONSET) -> Piecewise:
    """smooth_sign(b) on |x| <= d, sign(x) (1 - ((|x| - d)/(4 - d))^k) beyond: |.| < 1 there."""
    right = 1.0 - Piecewise.ramp(d, k, 1.0 / (HALF_WIDTH - d))
    left = Piecewise.ramp(-d, k, 1.0 / (HALF_WIDTH - d), right=False) - 1.0
    outer = Piecewise((-d, d), (left.pieces[0], {}, right.pieces[-1]))
    inner = Piecewise.window(-d, d, smooth_sign(b))
    return inner + outer


# --- the cases ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class ExactSolution:
    """Exact fields (functions of x, y) and traces on Gamma_C (functions of x)."""

    u: tuple[Piecewise, Piecewise]
    sigma: tuple[tuple[Piecewise, Piecewise], tuple[Piecewise, Piecewise]]
    div_sigma: tuple[Piecewise, Piecewise]
    eta: Piecewise
    gap: Piecewise
    lam_n: Piecewise
    lam_t: Piecewise
    sigma_n: Piecewise
    sigma_t: Piecewise
    friction_bound: Piecewise

    @property
    def degree(self) -> int:
        """Largest polynomial degree of u, sigma, div sigma and eta on one strip."""
        parts = [*self.u, *self.sigma[0], *self.sigma[1], *self.div_sigma, self.eta]
        return max(p.degree for p in parts)


@dataclass(frozen=True)
class ManufacturedCase:
    """A manufactured contact problem on the rectangle of Example 3.46 (see the module doc).

    The traces on Gamma_C are functions of x; ``contact_set`` and ``stick_set`` are the
    exact sets as intervals of x (the stick set: contact points with u_t = 0 and
    |sigma_t| < F; empty without friction).
    """

    name: str
    description: str
    law: str
    lam_t: Piecewise
    u_n: Piecewise
    lam_n: Piecewise
    sigma_n: Piecewise
    sigma_t: Piecewise
    contact_set: tuple[tuple[float, float], ...]
    stick_set: tuple[tuple[float, float], ...] = ()
    mu_f: float = 0.0
    tresca_bound: Piecewise = field(default_factory=lambda: Piecewise.constant(0.0))
    interior: tuple[Piecewise, Piecewise] = field(default_factory=lambda: (
        0.002 * (1.0 + _x() / 4.0), -0.001 * (1.0 + _x() * _x() / 16.0)))
    material: Material = field(default_factory=lambda: Material(E, NU))

    @cached_property
    def exact(self) -> ExactSolution:
        lam, mu = self.material.lame
        Y = Piecewise.y() - Y0
        b1 = self.sigma_t / mu + self.u_n.dx()
        b2 = (self.sigma_n - lam * self.lam_t.dx()) / (lam + 2 * mu)
        u = (self.lam_t + Y * b1 + Y * Y * self.interior[0],
             -self.u_n + Y * b2 + Y * Y * self.interior[1])
        grad = [[u[i].dx(), u[i].dy()] for i in range(2)]
        div_u = grad[0][0] + grad[1][1]
        sigma = tuple(tuple(mu * (grad[i][j] + grad[j][i]) + (lam * div_u if i == j else 0.0)
                            for j in range(2)) for i in range(2))
        div_sigma = tuple(sigma[i][0].dx() + sigma[i][1].dy() for i in range(2))
        eta = 0.5 * (grad[0][1] - grad[1][0])
        if self.law == "coulomb":
            bound = self.mu_f * (-self.sigma_n)
        elif self.law == "tresca":
            bound = self.tresca_bound
        else:
            bound = Piecewise.constant(0.0)
        return ExactSolution(u, sigma, div_sigma, eta, self.u_n + self.lam_n, self.lam_n,
                             self.lam_t, self.sigma_n, self.sigma_t, bound)

    def scene(self, method: str = "auto", level: int = 1, ends: str = "consistent",
              order: int = 0) -> Scene:
        """The validated scene: f = -div sigma, t0 = sigma n on the top, u_D = u on the sides.

        ``method``: ``solver.method``; ``ends``: ``contact.ends`` (the exact multipliers
        vanish at the ends of Gamma_C, so "consistent" and "thesis" pose the same problem);
        ``order``: ``discretisation.order`` k, with the multipliers of its default family.
        """
        ex = self.exact
        traction = [ex.sigma[0][1].text(), ex.sigma[1][1].text()]   # n = (0, 1) on the top
        sc = Scene(name=f"manufactured-{self.name}",
                   geometry=Geometry(kind="thesis-3.46", level=level),
                   boundary={"dirichlet": ["left", "right"], "neumann": ["top"],
                             "contact": ["bottom"]},
                   material=Material(self.material.E, self.material.nu),
                   loads=Loads(body_force=[(-d).text() for d in ex.div_sigma],
                               traction=traction,
                               displacement=[c.text() for c in ex.u]),
                   # max(0, .): the expanded polynomial is zero at the clamped ends only up
                   # to round-off, and the scene's gap must be >= 0
                   contact=Contact(gap=f"max(0, {ex.gap.text()})", ends=ends),
                   friction=Friction(law=self.law, mu=self.mu_f,
                                     bound=self.tresca_bound.text()),
                   solver=Solver(method=method),
                   discretisation=Discretisation(order=order))
        validate(sc)
        return sc


def frictionless_case(a: float = 2.0, name: str | None = None,
                      onset: int = ONSET, gap: str = "quartic") -> ManufacturedCase:
    """Contact on [-a, a] (sigma_n = -P (1 - x^2/a^2)_+^p), lift-off towards the clamped ends.

    Parameters
    ----------
    a : float
        Half the length of the contact set.
    name : str, optional
        The case's name (default ``frictionless-a<a>``), followed by ``-onset<p>`` for
        p != 2 and ``-gap-quadratic`` for the quadratic gap.
    onset : int
        p >= 2: sigma_n and lambda_n grow like d^p from the end points +-a, d the distance
        to the nearer one (u_n and lambda_t are polynomials). Their p-th derivatives jump
        there, so sigma_n, lambda_n lie in H^{p+1/2-eps}(Gamma_C); u = (.., -u_n + Y b_2)
        with b_2 carrying sigma_n lies in H^{p+1/2-eps}(Omega) and sigma, which carries
        Y sigma_n'(x) in sigma_12, in H^{p-1/2-eps}(Omega), the jumps sitting on the lines
        x = +-a. On a mesh that cuts these lines the best L^2 approximation of sigma is
        O(h^{min(k+1, p-1/2)}): order k needs p >= k + 2. On Example 3.46's structured
        mesh with a = 2 the lines are mesh lines and sigma is a polynomial on every
        triangle, so any p >= 2 verifies any k; there p decides the contact ends instead.
        A margin d^p next to an end (the pressure on the contact side, lambda_n on the
        separated side) must dominate the O(h^{k+1}) errors of the Bernstein coefficients
        that decide the set: p = 2 recovers the set exactly at k = 0, 1, 2, while at
        k = 1, 2 p = 3 misclassifies one fine edge next to each end on the finer levels
        and p = 4 more as h falls (docs/theory/order.md, "Verification per order"). The
        default p = 2 is therefore the onset of every order's verification.
    gap : {"quartic", "quadratic"}
        The normal displacement on Gamma_C: u_n = APPROACH (1 - x^2/16)^2 (quartic, the
        general case) or u_n = APPROACH (1 - x^2/16) (quadratic). Both vanish at the
        clamped ends and are positive inside, so g = u_n + lambda_n >= 0; on the contact
        zone lambda_n = 0 and g = u_n. The facet multipliers of order k see g through its
        P_k interpolant g_h at the control points of every fine edge e = (x_0, x_1) (at
        k = 2: x_0, the midpoint x_m and x_1), and sigma sees the gap's error only through
        int_e (g - g_h) tau_n ds with tau_n in P_k(e), that is through Pi_k g - g_h (Pi_k
        the L^2(e) projection). At k = 1 the interpolation error
        -g^(2) (x - x_0)(x_1 - x) / 2 is even about the midpoint: Pi_1 g - g_h =
        -g^(2) h^2 / 12 + O(h^3), a constant per edge that varies smoothly along Gamma_C,
        and nothing is lost. At k = 2 the error g^(3) (x - x_0)(x - x_m)(x - x_1) / 6 is
        odd about the midpoint: Pi_2 g - g_h is a saw of amplitude c g^(3) h^3 that jumps
        at every vertex, O(h^{5/2}) in H^{1/2}(Gamma_C), which limits sigma to order
        k + 1/2 and the pressure to k asymptotically (an even k >= 2 loses half an order,
        an odd k nothing). The quadratic u_n has g^(3) = 0 on the contact zone, so
        g_h = g there for k >= 2: the case measures the method alone, at order k + 1 for
        k = 0, 1, 2 (docs/theory/order.md, "What limits k = 2: the interpolated gap").
    """
    if onset < 2:
        raise ValueError(f"onset must be >= 2 (sigma_n in C^1), got {onset}")
    if gap not in GAPS:
        raise ValueError(f"gap must be one of {', '.join(GAPS)}, got {gap!r}")
    x = _x()
    suffix = ("" if onset == ONSET else f"-onset{onset}") + (
        "" if gap == "quartic" else f"-gap-{gap}")
    profile = 1.0 - x * x / 16.0
    return ManufacturedCase(
        name=(name or f"frictionless-a{a:g}") + suffix,
        description=f"frictionless; contact set [-{a:g}, {a:g}]{suffix}",
        law="none",
        lam_t=SLIDE * (x / 4.0) * (1.0 - x * x / 16.0),
        u_n=APPROACH * (profile ** 2 if gap == "quartic" else profile),
        lam_n=LIFT * (bump(-HALF_WIDTH, -a, onset) + bump(a, HALF_WIDTH, onset)),
        sigma_n=-PRESSURE * cap(a, onset),
        sigma_t=Piecewise.constant(0.0),
        contact_set=((-a, a),))


def tresca_case(b: float = 1.0, a: float = 2.0, d: float = 3.0, bound: float = 1.0,
                name: str | None = None) -> ManufacturedCase:
    """Tresca, F = ``bound`` on all of Gamma_C: contact [-a, a], slip on b < |x| < d.

    Stick where |x| <= b or |x| >= d (|sigma_t| < F, u_t = 0), slip in between with
    sigma_t = F sign(x) = F sign(lambda_t); b < a < d, so the stick set in contact is [-b, b].
    """
    return _friction_case(
        a, name or f"tresca-b{b:g}-a{a:g}-d{d:g}", "tresca",
        f"Tresca F = {bound:g}; contact [-{a:g}, {a:g}], stick [-{b:g}, {b:g}] "
        f"and |x| >= {d:g}",
        lam_t=SLIDE * (bump(b, d, ONSET + 1) - bump(-d, -b, ONSET + 1)),
        sigma_t=bound * stick_towards_ends(b, d), stick_set=((-b, b),),
        tresca_bound=Piecewise.constant(bound))


def coulomb_case(b: float = 2.0 / 3.0, a: float = 7.0 / 3.0, mu_f: float = 0.5,
                 name: str | None = None) -> ManufacturedCase:
    """Coulomb, F = mu_f |sigma_n|: contact [-a, a], stick [-b, b], slip on b < |x| <= a."""
    return _friction_case(
        a, name or f"coulomb-b{b:.4g}-a{a:.4g}", "coulomb",
        f"Coulomb mu_f = {mu_f:g}; contact [-{a:.4g}, {a:.4g}], stick [-{b:.4g}, {b:.4g}]",
        lam_t=SLIDE * (bump(b, HALF_WIDTH, ONSET + 1) - bump(-HALF_WIDTH, -b, ONSET + 1)),
        sigma_t=mu_f * PRESSURE * cap(a) * smooth_sign(b), stick_set=((-b, b),), mu_f=mu_f)


def _friction_case(a: float, name: str, law: str, description: str,
                   **friction) -> ManufacturedCase:
    """The frictionless case with contact [-a, a] and the tangential fields ``friction``
    (lam_t, sigma_t, stick_set and the law's bound) of a friction law."""
    base = frictionless_case(a)
    return ManufacturedCase(name=name, description=description, law=law, u_n=base.u_n,
                            lam_n=base.lam_n, sigma_n=base.sigma_n, contact_set=((-a, a),),
                            **friction)


CASES = {
    # contact-set end points on coarse (h~) nodes on every level
    "frictionless": lambda: frictionless_case(2.0, "frictionless"),
    "tresca": lambda: tresca_case(1.0, 2.0, 3.0, 1.0, "tresca"),
    "coulomb-nodes": lambda: coulomb_case(1.0, 2.0, 0.5, "coulomb-nodes"),
    # end points at a third of an h~ edge on every level (7/3, 2/3 are not dyadic)
    "frictionless-offnode": lambda: frictionless_case(7.0 / 3.0, "frictionless-offnode"),
    "coulomb": lambda: coulomb_case(2.0 / 3.0, 7.0 / 3.0, 0.5, "coulomb"),
}


def manufactured_case(name: str) -> ManufacturedCase:
    """One of :data:`CASES` by name."""
    if name not in CASES:
        raise KeyError(f"unknown manufactured case {name!r}; known: {', '.join(CASES)}")
    return CASES[name]()
