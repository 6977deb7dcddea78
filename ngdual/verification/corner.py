"""The L-shaped domain with Williams' corner singularity: a problem with a known solution.

The L-shape (-1, 1)^2 without the quarter (0, 1) x (-1, 0) has a re-entrant corner
of interior angle 2 omega = 3 pi / 2 at the origin. With traction-free sides at the
corner (``corner_v``, ``corner_h``: Gamma_N) and u = u_exact on the other four
sides (Gamma_D), the exact solution is Williams' symmetric (mode I) corner field

    u ~ r^alpha g(theta),   sigma ~ r^(alpha - 1),
    alpha in (0, 1) the root of sin(2 omega alpha) + alpha sin(2 omega) = 0,

so sigma is in H^(alpha - eps) only and uniform refinement converges like
h^alpha ~ N^(-alpha/2), while adaptive refinement restores N^(-1/2) for PEERS
(Section 4.2's question, asked on a problem whose error can be computed).

>>> round(corner_exponent(), 4)
0.5445
"""

from __future__ import annotations

import math

import ngsolve as ngs

from ..expr import Expression
from ..quantities import fields
from ..scene import Geometry, Loads, Material, Scene, validate
from ..solution import Solution

OMEGA = 3 * math.pi / 4  # half the interior angle at the re-entrant corner
POINTS = [(-1, -1), (0, -1), (0, 0), (1, 0), (1, 1), (-1, 1)]
LABELS = ["bottom", "corner_v", "corner_h", "right", "top", "left"]


def corner_exponent(omega: float = OMEGA) -> float:
    """alpha in (0, 1) with sin(2 omega alpha) + alpha sin(2 omega) = 0 (Newton from 1/2)."""
    alpha = 0.5
    for _ in range(30):
        alpha -= ((math.sin(2 * omega * alpha) + alpha * math.sin(2 * omega))
                  / (2 * omega * math.cos(2 * omega * alpha) + math.sin(2 * omega)))
    return alpha


def corner_displacement(E: float = 1.0, nu: float = 0.3) -> list[str]:
    """Williams' symmetric mode at the corner, plane strain, as scene formulas in x, y.

    In polar coordinates (r, theta) about the corner, theta from the bisector (-1, 1)
    of the domain: 2 mu u_r = r^a (-(a+1) cos((a+1) th) + (kappa - a) B cos((a-1) th)),
    2 mu u_th = r^a ((a+1) sin((a+1) th) + (kappa + a) B sin((a-1) th)),
    kappa = 3 - 4 nu, B = -cos((a+1) omega) / cos((a-1) omega).
    """
    a, (_, mu) = corner_exponent(), Material(E, nu).lame
    kappa = 3 - 4 * nu
    b = -math.cos((a + 1) * OMEGA) / math.cos((a - 1) * OMEGA)
    r = "sqrt(x*x + y*y)"
    th = "atan2(-(x + y), y - x)"  # the angle from the bisector
    ph = f"({th} + {OMEGA!r})"     # the polar angle of (x, y)
    ur = (f"({r})**{a!r}*(-({a + 1!r})*cos({a + 1!r}*{th}) "
          f"+ ({(kappa - a) * b!r})*cos({a - 1!r}*{th}))/{2 * mu!r}")
    ut = (f"({r})**{a!r}*(({a + 1!r})*sin({a + 1!r}*{th}) "
          f"+ ({(kappa + a) * b!r})*sin({a - 1!r}*{th}))/{2 * mu!r}")
    return [f"({ur})*cos({ph}) - ({ut})*sin({ph})", f"({ur})*sin({ph}) + ({ut})*cos({ph})"]


def l_shape_scene(E: float = 1.0, nu: float = 0.3, maxh: float = 0.5) -> Scene:
    """The validated scene: Williams' displacement on Gamma_D, free sides at the corner."""
    scene = Scene("l-shape-corner", Geometry(kind="polygon", points=POINTS, labels=LABELS,
                                             maxh=maxh),
                  {"dirichlet": ["bottom", "right", "top", "left"],
                   "neumann": ["corner_v", "corner_h"]},
                  material=Material(E, nu), loads=Loads(displacement=corner_displacement(E, nu)))
    validate(scene)
    return scene


def exact_fields(E: float = 1.0, nu: float = 0.3):
    """(u, sigma, eta) of the exact solution as NGSolve coefficient functions."""
    u = ngs.CF(tuple(Expression(c).coefficient() for c in corner_displacement(E, nu)))
    grad = ngs.CF((u[0].Diff(ngs.x), u[0].Diff(ngs.y), u[1].Diff(ngs.x), u[1].Diff(ngs.y)),
                  dims=(2, 2))
    strain = 0.5 * (grad + grad.trans)
    lam, mu = Material(E, nu).lame
    sigma = 2 * mu * strain + lam * ngs.Trace(strain) * ngs.Id(2)
    return u, sigma, 0.5 * (grad[0, 1] - grad[1, 0])


def exact_error(solution: Solution, exact=None) -> float:
    """(||sigma - sigma_h||^2 + ||div sigma_h||^2 + ||u - u_h||^2 + ||eta - eta_h||^2)^{1/2}.

    ``exact`` = :func:`exact_fields` of the scene's material (default E = 1, nu = 0.3);
    div sigma = 0 exactly, so the H(div) error of sigma has ||div sigma_h|| as its second part.
    """
    u, sigma, eta = exact_fields() if exact is None else exact
    f = fields(solution)
    mesh = solution.problem.fes.mesh

    def integral(cf):
        return ngs.Integrate(cf * ngs.dx(bonus_intorder=6), mesh)

    return math.sqrt(integral(ngs.InnerProduct(sigma - f.sigma, sigma - f.sigma))
                     + integral(f.div_sigma * f.div_sigma) + integral((u - f.u) * (u - f.u))
                     + integral((eta - f.eta) ** 2))
