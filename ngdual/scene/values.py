"""Checks of single values: types, finite and positive numbers, formulas, and how a value is shown
in an error message."""

from __future__ import annotations

import dataclasses
import math

from ..expr import Expression, ExpressionError
from .errors import Problems, SceneError
from .tables import ROLES, SECTIONS, Scene


def show(value, width: int = 60) -> str:
    """``repr(value)`` for a message, shortened (user input can be arbitrarily long)."""
    try:
        text = repr(value)
    except ValueError:  # an integer beyond Python's digit limit for str()
        text = f"<an integer of {value.bit_length()} bits>"
    return text if len(text) <= width else text[:width - 3] + "..."


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def finite(value) -> bool:
    """A number (not a bool) that is finite in double precision (huge integers are not)."""
    try:
        return _is_number(value) and math.isfinite(value)
    except OverflowError:
        return False


def positive(value, field_name: str, integer: bool = False) -> None:
    kind = int if integer else (int, float)
    if not isinstance(value, kind) or not finite(value) or value <= 0:
        raise SceneError(field_name, f"must be a positive {'integer' if integer else 'number'}, "
                                     f"got {show(value)}")


def expression(text, field_name: str) -> Expression:
    try:
        return Expression(text)
    except (ExpressionError, TypeError) as err:
        raise SceneError(field_name, str(err)) from None


def pair(values, field_name: str) -> list[Expression]:
    if not isinstance(values, (list, tuple)) or len(values) != 2:
        raise SceneError(field_name, f"must be a pair [x-component, y-component], got "
                                     f"{show(values)}")
    problems = Problems()
    out = []
    for i, v in enumerate(values):
        with problems.check():
            out.append(expression(v, f"{field_name}[{i}]"))
    problems.raise_any()
    return out


def tractions(value, neumann: list[str] | None) -> dict[str, list[Expression]]:
    """``loads.traction`` checked: one pair ``[tx, ty]`` for every side of Gamma_N, or a table
    keyed by the labels ``neumann`` of Gamma_N (a side not listed is traction-free).

    Returns ``{label: [tx, ty]}`` for every Gamma_N side; with ``neumann`` None (the
    boundary table is wrong) only the formulas are checked, and the labels given returned.
    """
    if not isinstance(value, (dict, list, tuple)):
        raise SceneError("loads.traction", 'must be a pair [tx, ty] or a table keyed by '
                                           'Gamma_N label, e.g. {top = ["0", "-1"]}, got '
                                           f"{show(value)}")
    if not isinstance(value, dict):
        both = pair(value, "loads.traction")
        return {label: both for label in neumann or []}
    problems = Problems()
    given = {}
    for label, formulas in value.items():
        if neumann is not None and label not in neumann:
            problems.add("loads.traction", f"{show(label)} is not a side of Gamma_N; the "
                                           "table is keyed by the labels of boundary.neumann"
                                           f" ({', '.join(neumann) or 'none'})")
            continue
        with problems.check():
            given[label] = pair(formulas, f"loads.traction.{label}")
    problems.raise_any()
    free = [Expression("0"), Expression("0")]
    return {label: given.get(label, free) for label in (given if neumann is None else neumann)}


# What each setting must be; the formulas (loads, contact.gap, friction.bound) are checked
# by parsing them, the tables of geometry (points, labels, arcs, side_maxh) entry by entry.
_TYPES = {"str": (str,), "int": (int,), "float": (int, float), "list": (list, tuple),
          "dict": (dict,), "bool": (bool,)}


_TYPE_NAMES = {"str": "a string", "int": "an integer", "float": "a number",
               "list": "a list", "dict": "a table", "bool": "true or false"}


def _is_kind(value, kind: str) -> bool:
    """``value`` is of the table type ``kind``; true and false are of kind bool only."""
    return isinstance(value, _TYPES[kind]) and (kind == "bool") == isinstance(value, bool)


FORMULAS = {"contact.gap", "friction.bound", "loads.body_force", "loads.traction",
             "loads.displacement"}


def field_type_problems(section: str, obj) -> list[tuple[str, str]]:
    """``(field, message)`` for every setting of one section whose type is wrong."""
    found = []
    for f in dataclasses.fields(obj):
        key, value = f"{section}.{f.name}", getattr(obj, f.name)
        kinds = [k.strip() for k in str(f.type).split("|")]
        if key in FORMULAS or (value is None and "None" in kinds):
            continue
        kinds = [k for k in kinds if k != "None"]
        if not any(_is_kind(value, k) for k in kinds):
            found.append((key, f"must be {', or '.join(_TYPE_NAMES[k] for k in kinds)}, got "
                               f"{show(value)}"))
    return found


def type_problems(scene: Scene) -> list[tuple[str, str]]:
    """``(field, message)`` for every setting of ``scene`` whose type is wrong."""
    found = []
    if not isinstance(scene.name, str):
        found.append(("name", f"must be a string, got {show(scene.name)}"))
    for section, cls in SECTIONS.items():
        obj = getattr(scene, section)
        if not isinstance(obj, cls):
            found.append((section, f"must be a {cls.__module__}.{cls.__name__}, got "
                                   f"{type(obj).__name__}"))
            continue
        found += field_type_problems(section, obj)
    if not isinstance(scene.boundary, dict):
        found.append(("boundary", f"must be a table role -> labels, got {show(scene.boundary)}"))
        return found
    for role, labels in scene.boundary.items():
        if role not in ROLES:
            found.append((f"boundary.{role}", f"unknown role; use one of {', '.join(ROLES)}"))
        elif not isinstance(labels, (list, tuple)) or not all(isinstance(lab, str)
                                                              for lab in labels):
            found.append((f"boundary.{role}", f"must be a list of side labels, got "
                                              f"{show(labels)}"))
    return found
