"""Exact calculus of piecewise polynomials in x (pieces: polynomials in x and y).

A :class:`Piecewise` is a function of ``(x, y)`` that is a polynomial on each of
the strips ``x < b_1``, ``b_1 < x < b_2``, ..., ``x > b_n``. Sums, products and
the partial derivatives are exact (up to floating-point coefficients), so the body
force, traction and gap of a manufactured solution follow from the displacement
without a computer algebra package, and the result is written as a scene formula
(nested ``ifpos``, see :mod:`ngdual.expr`) or evaluated with NumPy.

A polynomial is a dict ``{(i, j): c}`` meaning the sum of ``c x^i y^j``.

>>> ramp = Piecewise.ramp(1.0, 3)                 # (x - 1)_+^3
>>> ramp.dx().numpy([0.0, 2.0], [0.0, 0.0])
array([0., 3.])
>>> (Piecewise.poly({(0, 1): 2.0}) * ramp).degree  # 2 y (x - 1)^3
4
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np

Poly = dict  # {(i, j): c}, the polynomial sum of c x^i y^j


def poly_add(*polys: Poly) -> Poly:
    out: Poly = {}
    for p in polys:
        for mono, c in p.items():
            out[mono] = out.get(mono, 0.0) + c
    return {mono: c for mono, c in out.items() if c != 0}


def poly_scale(p: Poly, s: float) -> Poly:
    return {mono: s * c for mono, c in p.items() if s * c != 0}


def poly_mul(p: Poly, q: Poly) -> Poly:
    return poly_add(*({(i + k, j + m): c * d} for (i, j), c in p.items()
                      for (k, m), d in q.items()))


def poly_dx(p: Poly) -> Poly:
    return {(i - 1, j): i * c for (i, j), c in p.items() if i > 0}


def poly_dy(p: Poly) -> Poly:
    return {(i, j - 1): j * c for (i, j), c in p.items() if j > 0}


def poly_mirror(p: Poly) -> Poly:
    """p(-x, y)."""
    return {(i, j): (-c if i % 2 else c) for (i, j), c in p.items()}


def poly_power_of_linear(shift: float, scale: float, k: int) -> Poly:
    """(scale (x - shift))^k expanded."""
    return {(i, 0): comb(k, i) * scale**k * (-shift) ** (k - i) for i in range(k + 1)
            if comb(k, i) * scale**k * (-shift) ** (k - i) != 0}


def poly_text(p: Poly) -> str:
    """A scene formula in x, y (see :mod:`ngdual.expr`)."""
    terms = []
    for (i, j), c in sorted(p.items()):
        factors = [f"({c!r})"] + ([f"x**{i}"] if i else []) + ([f"y**{j}"] if j else [])
        terms.append("*".join(factors))
    return " + ".join(terms) or "0"


def poly_numpy(p: Poly, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    out = np.zeros(np.broadcast(x, y).shape)
    for (i, j), c in p.items():
        out = out + c * x**i * y**j
    return out


def poly_degree(p: Poly) -> int:
    return max((i + j for i, j in p), default=0)


@dataclass(frozen=True)
class Piecewise:
    """A function that is a polynomial in (x, y) on each strip between the breakpoints in x.

    ``pieces[m]`` holds on ``breaks[m-1] < x < breaks[m]`` (with ``breaks[-1] = -inf``
    and ``breaks[len(breaks)] = +inf``).
    """

    breaks: tuple[float, ...]
    pieces: tuple[Poly, ...]

    def __post_init__(self):
        if len(self.pieces) != len(self.breaks) + 1:
            raise ValueError("need one more piece than breakpoints")
        if any(b >= c for b, c in zip(self.breaks, self.breaks[1:])):
            raise ValueError(f"breakpoints must increase: {self.breaks}")

    # --- construction -------------------------------------------------------------------------

    @classmethod
    def poly(cls, p: Poly) -> Piecewise:
        """One polynomial everywhere."""
        return cls((), (poly_add(p),))

    @classmethod
    def constant(cls, c: float) -> Piecewise:
        return cls.poly({(0, 0): float(c)} if c else {})

    @classmethod
    def x(cls) -> Piecewise:
        return cls.poly({(1, 0): 1.0})

    @classmethod
    def y(cls) -> Piecewise:
        return cls.poly({(0, 1): 1.0})

    @classmethod
    def ramp(cls, at: float, k: int, scale: float = 1.0, right: bool = True) -> Piecewise:
        """(scale (x - at))_+^k if ``right``, else (scale (at - x))_+^k (zero on the other side)."""
        power = poly_power_of_linear(at, scale if right else -scale, k)
        return cls((float(at),), ({}, power) if right else (power, {}))

    @classmethod
    def window(cls, left: float, right: float, inside: Piecewise) -> Piecewise:
        """``inside`` on left < x < right, zero elsewhere."""
        box = cls((float(left), float(right)), ({}, {(0, 0): 1.0}, {}))
        return box * inside

    # --- algebra ------------------------------------------------------------------------------

    def _on(self, breaks: tuple[float, ...]) -> tuple[Poly, ...]:
        """The pieces on the finer partition ``breaks`` (a superset of ``self.breaks``)."""
        out = []
        for m in range(len(breaks) + 1):
            # a point inside strip m of the finer partition
            if m == 0:
                probe = breaks[0] - 1 if breaks else 0.0
            elif m == len(breaks):
                probe = breaks[-1] + 1
            else:
                probe = 0.5 * (breaks[m - 1] + breaks[m])
            out.append(self.pieces[int(np.searchsorted(self.breaks, probe))])
        return tuple(out)

    def _combine(self, other: Piecewise, op) -> Piecewise:
        breaks = tuple(sorted(set(self.breaks) | set(other.breaks)))
        pieces = tuple(op(p, q) for p, q in zip(self._on(breaks), other._on(breaks)))
        return Piecewise(breaks, pieces).simplified()

    def simplified(self) -> Piecewise:
        """Drop breakpoints between identical pieces."""
        breaks, pieces = [], [self.pieces[0]]
        for b, p in zip(self.breaks, self.pieces[1:]):
            if p == pieces[-1]:
                continue
            breaks.append(b)
            pieces.append(p)
        return Piecewise(tuple(breaks), tuple(pieces))

    @staticmethod
    def _lift(other) -> Piecewise:
        return other if isinstance(other, Piecewise) else Piecewise.constant(float(other))

    def __add__(self, other) -> Piecewise:
        return self._combine(self._lift(other), poly_add)

    __radd__ = __add__

    def __neg__(self) -> Piecewise:
        return self * -1.0

    def __sub__(self, other) -> Piecewise:
        return self + (-self._lift(other))

    def __rsub__(self, other) -> Piecewise:
        return self._lift(other) - self

    def __mul__(self, other) -> Piecewise:
        if not isinstance(other, Piecewise):
            s = float(other)
            return Piecewise(self.breaks, tuple(poly_scale(p, s) for p in self.pieces)).simplified()
        return self._combine(other, poly_mul)

    __rmul__ = __mul__

    def __truediv__(self, s: float) -> Piecewise:
        return self * (1.0 / float(s))

    def __pow__(self, k: int) -> Piecewise:
        out = Piecewise.constant(1.0)
        for _ in range(int(k)):
            out = out * self
        return out

    def dx(self) -> Piecewise:
        """d/dx piece by piece (the function must be continuous across the breakpoints)."""
        return Piecewise(self.breaks, tuple(poly_dx(p) for p in self.pieces)).simplified()

    def dy(self) -> Piecewise:
        return Piecewise(self.breaks, tuple(poly_dy(p) for p in self.pieces)).simplified()

    def mirrored(self) -> Piecewise:
        """f(-x, y)."""
        return Piecewise(tuple(-b for b in reversed(self.breaks)),
                         tuple(poly_mirror(p) for p in reversed(self.pieces)))

    def at_y(self, y0: float) -> Piecewise:
        """f(x, y0) as a function of x alone."""
        def restrict(p):
            return poly_add(*({(i, 0): c * y0**j} for (i, j), c in p.items()))
        return Piecewise(self.breaks, tuple(restrict(p) for p in self.pieces)).simplified()

    # --- output -------------------------------------------------------------------------------

    @property
    def degree(self) -> int:
        return max(poly_degree(p) for p in self.pieces)

    def text(self) -> str:
        """The scene formula: nested ``ifpos(x - b, right, left)``."""
        out = poly_text(self.pieces[-1])
        for m in range(len(self.breaks), 0, -1):
            out = f"ifpos(x - ({self.breaks[m - 1]!r}), {out}, {poly_text(self.pieces[m - 1])})"
        return out

    def numpy(self, x, y) -> np.ndarray:
        """Values at the points (x, y); on a breakpoint the piece to its right."""
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        strip = np.searchsorted(self.breaks, x, side="right")
        out = np.zeros(x.shape)
        for m, p in enumerate(self.pieces):
            mask = strip == m
            if mask.any():
                out[mask] = poly_numpy(p, x[mask], y[mask])
        return out

    def jumps(self, derivatives: int = 0, ys=(0.0,)) -> list[float]:
        """Largest jump across the breakpoints (at the heights ``ys``) of f, f_x, ... up to
        the ``derivatives``-th x-derivative: zeros mean f is C^derivatives in x."""
        out, f = [], self
        ys = np.asarray(ys, dtype=float)
        for _ in range(derivatives + 1):
            worst = 0.0
            for m, b in enumerate(f.breaks):
                left = poly_numpy(f.pieces[m], np.full_like(ys, b), ys)
                right = poly_numpy(f.pieces[m + 1], np.full_like(ys, b), ys)
                worst = max(worst, float(np.max(np.abs(right - left))))
            out.append(worst)
            f = f.dx()
        return out
