"""Scalar expressions in the coordinates ``x``, ``y`` used by scenes.

Scenes give loads, gaps and friction bounds as short formulas such as
``"-800*ifpos(4 - x*x, (1 - x*x/4)**2, 0)"``. One parsed expression is
evaluated with two back ends: NumPy (for validation and plotting) and NGSolve
coefficient functions (for assembly). Only a whitelist of names is accepted,
so a scene file can never execute arbitrary code, and evaluation is bounded:
a formula has at most ``MAX_LENGTH`` characters and ``MAX_NODES`` syntax nodes,
functions take their exact number of arguments, and every constant subexpression
is folded once in floating point at parse time, so a power tower such as
``10**10**10`` (which Python's integers would try to compute digit by digit) or
``1/0`` is refused there instead of hanging or failing during assembly.

>>> Expression("abs(x) + 1").numpy(np.array([-2.0, 3.0]), np.zeros(2))
array([3., 4.])
"""

from __future__ import annotations

import ast
import functools
import math
import operator
import sys
import warnings
from dataclasses import dataclass, field

import numpy as np

_ARITY = {"abs": 1, "sqrt": 1, "exp": 1, "log": 1, "sin": 1, "cos": 1, "tan": 1, "atan": 1,
          "atan2": 2, "ifpos": 3, "min": 2, "max": 2}
_FUNCTIONS = tuple(_ARITY)
MAX_LENGTH = 20_000   # characters; the longest shipped (manufactured) formulas have ~2 500
MAX_NODES = 10_000    # syntax nodes
MAX_DEPTH = 200       # nesting of operations and calls (shipped formulas: <= 24)
_CONSTANTS = {"pi": np.pi, "e": np.e}
_OPERATORS = (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.USub, ast.UAdd)


class ExpressionError(ValueError):
    """Raised for a formula that does not parse or uses unknown names."""


def quote(text: str, width: int = 60) -> str:
    """The formula quoted for a one-line message (long ones shortened)."""
    return repr(text if len(text) <= width else text[:width - 3] + "...")


def _check(node: ast.AST, text: str) -> None:
    callees = {id(sub.func) for sub in ast.walk(node) if isinstance(sub, ast.Call)}
    for count, sub in enumerate(ast.walk(node)):
        if count > MAX_NODES:
            raise ExpressionError(f"formula too long: more than {MAX_NODES} terms")
        if isinstance(sub, (ast.Expression, ast.Load, ast.BinOp, ast.UnaryOp) + _OPERATORS):
            continue
        if isinstance(sub, ast.Constant):
            # bool is an int subclass: True/False would silently mean 1/0
            if isinstance(sub.value, (int, float)) and not isinstance(sub.value, bool):
                continue
            raise ExpressionError(f"{repr(sub.value)[:40]} is not a number, in {quote(text)}")
        if isinstance(sub, ast.Name):
            if sub.id in _FUNCTIONS and id(sub) not in callees:
                raise ExpressionError(f"{sub.id!r} is a function: call it, e.g. "
                                      f"{sub.id}({', '.join('xyx'[:_ARITY[sub.id]])}), "
                                      f"in {quote(text)}")
            if sub.id in ("x", "y") or sub.id in _CONSTANTS or sub.id in _FUNCTIONS:
                continue
            raise ExpressionError(f"unknown name {sub.id!r} in {quote(text)} "
                                  f"(allowed: x, y, pi, e, {', '.join(_FUNCTIONS)})")
        if isinstance(sub, ast.Call):
            if not (isinstance(sub.func, ast.Name) and sub.func.id in _FUNCTIONS):
                name = sub.func.id if isinstance(sub.func, ast.Name) else ast.unparse(sub.func)
                raise ExpressionError(f"unknown name {name!r} in {quote(text)} "
                                      f"(functions: {', '.join(_FUNCTIONS)})")
            if sub.keywords or len(sub.args) != _ARITY[sub.func.id]:
                raise ExpressionError(f"{sub.func.id} takes {_ARITY[sub.func.id]} "
                                      f"argument{'s' * (_ARITY[sub.func.id] > 1)}, got "
                                      f"{len(sub.args) + len(sub.keywords)} in {quote(text)}")
            continue
        raise ExpressionError(f"unsupported syntax {type(sub).__name__} in {quote(text)}")


_FOLD_FUNCTIONS = {
    "abs": abs, "sqrt": math.sqrt, "exp": math.exp, "log": math.log, "sin": math.sin,
    "cos": math.cos, "tan": math.tan, "atan": math.atan, "atan2": math.atan2,
    "min": min, "max": max, "ifpos": lambda c, a, b: a if c > 0 else b,
}
_FOLD_OPERATORS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
                   ast.Div: operator.truediv, ast.Pow: operator.pow,
                   ast.USub: operator.neg, ast.UAdd: operator.pos}


def _fold(node: ast.AST, text: str, depth: int = 0) -> float | None:
    """The value of a constant subtree in floating point, None where it depends on x, y.

    Every constant operation is done once, in floats, so its size is bounded (an
    overflow, a division by zero or a complex power is refused here); the NumPy and
    NGSolve back ends then only ever see operations on floats of bounded size.
    """
    if depth > MAX_DEPTH:
        raise ExpressionError(f"formula nested too deeply (more than {MAX_DEPTH} levels) in "
                              f"{quote(text)}")
    if isinstance(node, ast.Expression):
        return _fold(node.body, text, depth)
    if isinstance(node, ast.Constant):
        try:
            return _finite(float(node.value), text)
        except OverflowError:
            return _finite(math.inf, text)
    if isinstance(node, ast.Name):
        return _CONSTANTS.get(node.id)
    if isinstance(node, ast.UnaryOp):
        value = _fold(node.operand, text, depth + 1)
        return None if value is None else _FOLD_OPERATORS[type(node.op)](value)
    if isinstance(node, ast.BinOp):
        args = [_fold(node.left, text, depth + 1), _fold(node.right, text, depth + 1)]
        operation = _FOLD_OPERATORS[type(node.op)]
    else:  # a call (the only other node _check lets through)
        args = [_fold(a, text, depth + 1) for a in node.args]
        operation = _FOLD_FUNCTIONS[node.func.id]
    if any(a is None for a in args):
        return None
    try:
        value = operation(*args)
    except ZeroDivisionError:
        raise ExpressionError(f"division by zero in {quote(text)}") from None
    except OverflowError:
        raise ExpressionError(f"a constant overflows (exceeds {sys.float_info.max:.3g}) in "
                              f"{quote(text)}") from None
    except ValueError:
        raise ExpressionError(f"{quote(ast.unparse(node))} is not defined (not a real number) in "
                              f"{quote(text)}") from None
    if isinstance(value, complex):
        raise ExpressionError(f"{quote(ast.unparse(node))} is not a real number in {quote(text)}")
    return _finite(float(value), text)


def _finite(value: float, text: str) -> float:
    if not math.isfinite(value):
        raise ExpressionError(f"a constant overflows (exceeds {sys.float_info.max:.3g}) in "
                              f"{quote(text)}")
    return value


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


@functools.lru_cache(maxsize=1024)
def _compiled(text: str) -> tuple[float | None, object]:
    """(the constant value or None, the code object) of a stripped formula, checked; cached
    by its text: the scene's formulas are read again on every mesh of an adaptive run."""
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"formula too long ({len(text)} characters, at most "
                              f"{MAX_LENGTH})")
    try:
        with warnings.catch_warnings():  # "invalid decimal literal" for 2x: an error below
            warnings.simplefilter("ignore", SyntaxWarning)
            tree = ast.parse(text, mode="eval")
    except SyntaxError as err:
        raise ExpressionError(f"cannot parse {quote(text)}: {err.msg}") from None
    except (RecursionError, MemoryError, ValueError):
        raise ExpressionError(f"formula too large to parse: {quote(text)}") from None
    _check(tree, text)
    return _fold(tree, text), compile(tree, "<scene expression>", "eval")


@dataclass(frozen=True)
class Expression:
    """A validated scalar formula in ``x`` and ``y``.

    Parameters
    ----------
    text : str
        The formula; a plain number is fine too.

    Examples
    --------
    >>> import numpy as np
    >>> import ngdual as nd
    >>> gap = nd.Expression("0.01 + 0.002*x**2")
    >>> gap.numpy(np.array([0.0, 2.0]), np.zeros(2))          # NumPy; .coefficient(): NGSolve
    array([0.01 , 0.018])
    """

    text: str
    _code: object = field(init=False, repr=False, compare=False)
    constant: float | None = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        if isinstance(self.text, bool) or not isinstance(self.text, (str, int, float)):
            raise ExpressionError(f"a formula must be a string or a number, got "
                                  f"{repr(self.text)[:60]}")
        text = str(self.text).strip()
        constant, code = _compiled(text)
        object.__setattr__(self, "constant", constant)
        object.__setattr__(self, "text", text)
        object.__setattr__(self, "_code", code)

    def numpy(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Evaluate at the points ``(x, y)``; returns an array of ``x``'s shape.

        Where the formula is not defined (``sqrt(-1)``, ``log(0)``, overflow) the value
        is inf or nan, without a warning: callers check finiteness where it matters.
        """
        x = np.asarray(x, dtype=float)
        with np.errstate(all="ignore"):
            value = eval(self._code, {"__builtins__": {}},
                         _numpy_namespace(x, np.asarray(y, float)))
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


def coefficient(formulas):
    """The NGSolve coefficient function of a formula, or of a vector or matrix of formulas.

    Parameters
    ----------
    formulas : str, float, list of str or list of lists of str
        A scalar formula in ``x``, ``y`` (:class:`Expression`), a vector ``[f_1, f_2]`` of
        them (as a scene writes its loads) or a matrix ``[[f_11, f_12], [f_21, f_22]]``.

    Returns
    -------
    ngsolve.CoefficientFunction
        Scalar, of dimension ``len(formulas)``, or of dims (rows, columns).

    Examples
    --------
    >>> import ngdual as nd
    >>> nd.coefficient(["x*y", "-x"]).dim, tuple(nd.coefficient([["1", "x"], ["x", "2"]]).dims)
    (2, (2, 2))
    """
    import ngsolve as ngs

    if isinstance(formulas, (str, int, float)):
        return Expression(formulas).coefficient()
    rows = list(formulas)
    if not rows:
        raise ExpressionError("a vector or matrix of formulas needs at least one entry")
    if all(isinstance(row, (str, int, float)) for row in rows):
        return ngs.CF(tuple(Expression(f).coefficient() for f in rows))
    rows = [list(row) for row in rows]
    if len({len(row) for row in rows}) != 1:
        raise ExpressionError(f"the rows of a matrix of formulas differ in length: "
                              f"{[len(row) for row in rows]}")
    return ngs.CF(tuple(Expression(f).coefficient() for row in rows for f in row),
                  dims=(len(rows), len(rows[0])))
