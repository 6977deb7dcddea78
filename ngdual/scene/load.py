"""Reading a scene: TOML files, the shipped scenes, ``section.key=value`` overrides."""

from __future__ import annotations

import copy
import dataclasses
from importlib import resources
from pathlib import Path

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11
    import tomli as tomllib

from .errors import Problems, SceneError, SceneTypeError
from .tables import ROLES, SECTIONS, Scene
from .validate import ensure_valid
from .values import show


def shipped_scenes() -> list[str]:
    """Names of the scenes shipped in :mod:`ngdual.scenes`."""
    folder = resources.files("ngdual.scenes")
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def read_toml(source: str | Path) -> tuple[str, dict]:
    if isinstance(source, bool) or not isinstance(source, (str, Path)):
        raise SceneTypeError("scene", f"must be a path or a shipped scene name, got "
                                      f"{type(source).__name__}")
    path = Path(source)
    if path.is_dir():
        raise SceneError("scene", f"{repr(str(path))} is a directory; give a TOML scene file "
                                  "inside it or the name of a shipped scene")
    if path.suffix == ".toml" or path.exists():
        if not path.is_file():
            raise SceneError("scene", f"no such scene file {repr(str(path))}")
        try:
            text, default_name = path.read_text(encoding="utf-8"), path.stem
        except (OSError, UnicodeDecodeError) as err:
            raise SceneError("scene", f"cannot read {repr(str(path))}: "
                                      f"{getattr(err, 'strerror', None) or err}") from None
    else:
        name = str(source)
        if name not in shipped_scenes():
            raise SceneError("scene", f"unknown scene {show(name)}; shipped scenes: "
                                      + ", ".join(shipped_scenes()))
        text = resources.files("ngdual.scenes").joinpath(name + ".toml").read_text()
        default_name = name
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError("scene", f"invalid TOML in {repr(str(source))}: {err}") from None
    return default_name, data


def _parse_value(text: str):
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_overrides(data: dict, overrides: list[str] | None) -> dict:
    """Apply ``--set section.key=value`` overrides (values parsed as TOML, else strings)."""
    if overrides is not None and (isinstance(overrides, str)
                                  or not all(isinstance(o, str) for o in overrides)):
        raise SceneTypeError("overrides", "must be a list of 'section.key=value' strings, got "
                                      f"{show(overrides)}")
    data = copy.deepcopy(data)
    for item in overrides or []:
        if "=" not in item:
            raise SceneError(item, "an override must read key=value, e.g. friction.mu=0.5")
        key, value = (s.strip() for s in item.split("=", 1))
        parts = key.split(".")
        if len(parts) == 1 and parts[0] == "name":
            data["name"] = value
            continue
        if len(parts) != 2 or (parts[0] not in SECTIONS and parts[0] != "boundary"):
            raise SceneError(key, "unknown key; use section.key with section in "
                                  + ", ".join(["boundary", *SECTIONS]))
        section = data.setdefault(parts[0], {})
        if not isinstance(section, dict):
            raise SceneError(parts[0], f"must be a table, got {show(section)}")
        section[parts[1]] = _parse_value(value)
    return data


GEOMETRY_REQUIRED = ('give kind = "thesis-3.46" (the rectangle [-4,4]x[-1,1] of Example 3.46) '
                     'or kind = "polygon" with points and labels')


def _build(name: str, data: dict) -> Scene:
    """The :class:`Scene` of a TOML document; every structural problem is reported at once."""
    problems = Problems()
    for key in sorted(set(data) - {"name", "description", "boundary", *SECTIONS}):
        problems.add(key, "unknown section; sections are "
                          + ", ".join(["name", "description", "boundary", *SECTIONS]))
    for key in ("name", "description"):
        if key in data and not isinstance(data[key], str):
            problems.add(key, f"must be a string, got {show(data[key])}")
    # a scene states its domain: no table silently becoming the thesis rectangle
    if "geometry" not in data:
        problems.add("geometry", "missing table: " + GEOMETRY_REQUIRED)
    elif isinstance(data["geometry"], dict) and "kind" not in data["geometry"]:
        problems.add("geometry.kind", "missing: " + GEOMETRY_REQUIRED)
    kwargs = {}
    for section, cls in SECTIONS.items():
        values = data.get(section, {})
        if not isinstance(values, dict):
            problems.add(section, f"must be a table [{section}], got {show(values)}")
            values = {}
        names = {f.name for f in dataclasses.fields(cls)}
        for key in values:
            if key not in names:
                problems.add(f"{section}.{key}", "unknown key; known keys: "
                             + ", ".join(sorted(names)))
        kwargs[section] = cls(**{k: v for k, v in values.items() if k in names})
    boundary = {}
    if "boundary" not in data:
        problems.add("boundary", "missing table: assign dirichlet/neumann/contact labels")
    elif not isinstance(data["boundary"], dict):
        problems.add("boundary", f"must be a table [boundary], got {show(data['boundary'])}")
    else:
        for role, labels in data["boundary"].items():
            if role not in ROLES:
                problems.add(f"boundary.{role}", f"unknown role; use one of {', '.join(ROLES)}")
                continue
            boundary[role] = [labels] if isinstance(labels, str) else labels
    problems.raise_any()
    scene = Scene(name=str(data.get("name", name)), boundary=boundary, **kwargs)
    # what the document sets, also where it repeats a default (see _settings_without_effect)
    scene.__dict__["_given"] = frozenset(f"{section}.{key}" for section in SECTIONS
                                         for key in data.get(section, {}))
    return scene


def load_scene(source: str | Path, overrides: list[str] | None = None) -> Scene:
    """Load a scene by file path or shipped name, apply overrides and validate it.

    >>> load_scene("thesis-3.46-frictionless", ["geometry.level=2"]).geometry.level
    2
    """
    name, data = read_toml(source)
    return scene_from_dict(data, overrides, name)


def scene_from_dict(data: dict, overrides: list[str] | None = None,
                    name: str = "scene") -> Scene:
    """The validated scene of a TOML document already parsed into ``data`` (a dict).

    >>> scene_from_dict({"geometry": {"kind": "thesis-3.46", "level": 1},
    ...                  "boundary": {"dirichlet": ["left", "right", "top", "bottom"]}}).name
    'scene'
    """
    if not isinstance(data, dict):
        raise SceneTypeError("scene", f"must be a table (dict) of sections, got "
                                      f"{type(data).__name__}")
    scene = _build(name, apply_overrides(data, overrides))
    ensure_valid(scene)
    return scene
