"""Scalar expressions in the coordinates ``x``, ``y`` used by scenes.

Scenes give loads, gaps and friction bounds as short formulas such as
``"-800*ifpos(4 - x*x, (1 - x*x/4)**2, 0)"``. One parsed expression is
evaluated with two back ends: NumPy (for validation and plotting) and NGSolve
coefficient functions (for assembly). Only a whitelist of names is accepted,
so a scene file can never execute arbitrary code.

>>> Expression("abs(x) + 1").numpy(np.array([-2.0, 3.0]), np.zeros(2))
array([3., 4.])
"""

from __future__ import annotations

import ast
from dataclasses import dataclass, field

import numpy as np

_FUNCTIONS = ("abs", "sqrt", "exp", "log", "sin", "cos", "tan", "atan", "atan2",
              "ifpos", "min", "max")
_CONSTANTS = {"pi": np.pi, "e": np.e}
_OPERATORS = (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.USub, ast.UAdd)


class ExpressionError(ValueError):
    """Raised for a formula that does not parse or uses unknown names."""


def _check(node: ast.AST, text: str) -> None:
    for sub in ast.walk(node):
        if isinstance(sub, (ast.Expression, ast.Load, ast.BinOp, ast.UnaryOp) + _OPERATORS):
            continue
        if isinstance(sub, ast.Constant) and isinstance(sub.value, (int, float)):
            continue
        if isinstance(sub, ast.Name):
            if sub.id in ("x", "y") or sub.id in _CONSTANTS or sub.id in _FUNCTIONS:
                continue
            raise ExpressionError(f"unknown name {sub.id!r} in {text!r} "
                                  f"(allowed: x, y, pi, e, {', '.join(_FUNCTIONS)})")
        if isinstance(sub, ast.Call):
            if isinstance(sub.func, ast.Name) and sub.func.id in _FUNCTIONS and not sub.keywords:
                continue
            name = sub.func.id if isinstance(sub.func, ast.Name) else ast.unparse(sub.func)
            raise ExpressionError(f"unknown name {name!r} in {text!r} "
                                  f"(functions: {', '.join(_FUNCTIONS)})")
        raise ExpressionError(f"unsupported syntax {type(sub).__name__} in {text!r}")


def _numpy_namespace(x, y) -> dict:
    return {
        "x": x, "y": y, **_CONSTANTS,
        "abs": np.abs, "sqrt": np.sqrt, "exp": np.exp, "log": np.log,
        "sin": np.sin, "cos": np.cos, "tan": np.tan, "atan": np.arctan,
        "atan2": np.arctan2, "min": np.minimum, "max": np.maximum,
        "ifpos": lambda c, a, b: np.where(np.asarray(c) > 0, a, b),
    }


def _ngsolve_namespace() -> dict:
    import ngsolve as ngs

    return {
        "x": ngs.x, "y": ngs.y, **_CONSTANTS,
        "abs": lambda a: ngs.IfPos(a, a, -a), "sqrt": ngs.sqrt, "exp": ngs.exp,
        "log": ngs.log, "sin": ngs.sin, "cos": ngs.cos, "tan": ngs.tan,
        "atan": ngs.atan, "atan2": ngs.atan2,
        "min": lambda a, b: ngs.IfPos(a - b, b, a),
        "max": lambda a, b: ngs.IfPos(a - b, a, b),
        "ifpos": ngs.IfPos,
    }


@dataclass(frozen=True)
class Expression:
    """A validated scalar formula in ``x`` and ``y``.

    Parameters
    ----------
    text : str
        The formula; a plain number is fine too.
    """

    text: str
    _code: object = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        text = str(self.text).strip()
        try:
            tree = ast.parse(text, mode="eval")
        except SyntaxError as err:
            raise ExpressionError(f"cannot parse {text!r}: {err.msg}") from None
        _check(tree, text)
        object.__setattr__(self, "text", text)
        object.__setattr__(self, "_code", compile(tree, "<scene expression>", "eval"))

    def numpy(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Evaluate at the points ``(x, y)``; returns an array of ``x``'s shape."""
        x = np.asarray(x, dtype=float)
        value = eval(self._code, {"__builtins__": {}}, _numpy_namespace(x, np.asarray(y, float)))
        return np.broadcast_to(np.asarray(value, dtype=float), x.shape).copy()

    def coefficient(self):
        """The NGSolve ``CoefficientFunction`` of this formula."""
        import ngsolve as ngs

        # NGSolve's unary functions import lazily, so __import__ must be reachable;
        # user text cannot name it (the parse check allows only whitelisted names)
        value = eval(self._code, {"__builtins__": {"__import__": __import__}},
                     _ngsolve_namespace())
        return value if isinstance(value, ngs.CoefficientFunction) else ngs.CF(float(value))

    def is_zero(self) -> bool:
        """True for the literal formula ``0``."""
        try:
            return float(self.text) == 0.0
        except ValueError:
            return False
