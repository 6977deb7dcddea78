"""The scene-key and command-line references as Markdown, generated from the code.

``python -m ngdual.studies.reference`` writes ``docs/reference/scene-keys.md`` (every key of
a scene file: its type and default from the dataclasses of :mod:`ngdual.scene`, where the
defaults live, its allowed values from the module's constants, its meaning from
:data:`MEANINGS`) and ``docs/reference/cli-commands.md`` (every subcommand and option of
:func:`ngdual.cli.parser`, with its default and help) into the source checkout;
``--check`` writes nothing and exits with status 1 when a checked-in file differs from
what the code gives. Both files are read in the checkout and on the documentation site.

>>> "| `friction.law` |" in scene_keys_markdown()
True
"""

from __future__ import annotations

import argparse
import dataclasses
import re
import sys
from pathlib import Path

from .sources import CHECKOUT

FOLDER = CHECKOUT / "docs" / "reference"
SCENE_KEYS = "scene-keys.md"
CLI_COMMANDS = "cli-commands.md"
COMMAND = "python -m ngdual.studies.reference"
WORDS = ("the file name", "required")     # defaults that are words, not values

MEANINGS = {
    "name": "Name of the scene in results and titles (default: the file name).",
    "description": "Free text describing the scene; not used by the solver.",
    "geometry.kind": "`thesis-3.46`: the rectangle [-4, 4] x [-1, 1] of Example 3.46 with "
                     "the structured mesh of Table 3.1 (sides `bottom`, `right`, `top`, "
                     "`left`); `polygon`: the polygon of `points`, meshed by netgen. Required.",
    "geometry.level": "Mesh level k: k - 1 uniform refinements of the initial mesh (new "
                      "boundary vertices lie on the curves).",
    "geometry.points": "Polygon vertices [x, y], counter-clockwise; side i runs from "
                       "points[i] to points[i+1] (cyclically). Only for `polygon`.",
    "geometry.labels": "One boundary label per side (letters, digits, `_`, `-`); the "
                       "`[boundary]` table assigns a condition to each label.",
    "geometry.maxh": "Largest element size of the netgen mesh of a `polygon` (level 1).",
    "geometry.arcs": "Table label -> centre [x, y]: those sides are the shorter circular "
                     "arcs around the centre between their end points.",
    "geometry.side_maxh": "Table label -> mesh size on those sides (netgen grades the mesh "
                          "from there to `maxh`).",
    "boundary.dirichlet": "Labels of Gamma_D: prescribed displacement `loads.displacement` "
                          "(at least one side is required).",
    "boundary.neumann": "Labels of Gamma_N: prescribed traction `loads.traction`.",
    "boundary.contact": "Labels of Gamma_C: unilateral contact with the rigid foundation, "
                        "with the friction law of `[friction]`.",
    "material.E": "Young's modulus E > 0 (plane strain).",
    "material.nu": "Poisson's ratio, -1 < nu < 1/2 (plane strain; PEERS does not lock as "
                   "nu -> 1/2).",
    "loads.body_force": "Body force f = [f_x, f_y], formulas in x and y.",
    "loads.traction": "Traction t_0 on Gamma_N, formulas in x and y: one pair [tx, ty] for "
                      "every side of Gamma_N, or a table keyed by Gamma_N label, "
                      "`{top = [\"0\", \"-800\"]}`, whose sides not listed are "
                      "traction-free.",
    "loads.displacement": "Displacement u_D on Gamma_D, formulas in x and y.",
    "contact.gap": "Gap g(x, y) >= 0 between Gamma_C and the foundation, along the outward "
                   "normal (formula; default 0). Give either `gap` or `foundation`.",
    "contact.foundation": "The foundation as a straight line `{point = [x, y], normal = "
                          "[nx, ny]}`, normal pointing towards the body; the gap follows "
                          "from the geometry.",
    "contact.htilde_factor": "h~ / h: the coarse mesh of the boundary multipliers phi, "
                             "lambda_t, lambda_n (3.61) has this many fine edges per edge.",
    "contact.hhat_factor": "h^ / h~ (1 or 2): the mesh of the friction multiplier nu. "
                           "2 is needed when the contact zone reaches the ends of Gamma_C, "
                           "e.g. g = 0 (Lemmas 3.29, 3.31).",
    "contact.ends": "Values of lambda_n, lambda_t at the ends of Gamma_C: `consistent` "
                    "(those the data prescribe where Gamma_C meets Gamma_D, free elsewhere) "
                    "or `thesis` (zero at every end, C_h~ of (3.61)).",
    "contact.discrete_gap": "The gap the discrete problem sees: `nodal` (g_h, the P1 "
                            "interpolant of g on the h~ mesh of lambda_n: no stress without "
                            "load, whatever the shape of g) or `thesis` (g itself in g(tau) of "
                            "(3.32), as in the thesis).",
    "friction.law": "Friction on Gamma_C: `none`, `tresca` (given bound F) or `coulomb` "
                    "(F = mu_f |sigma_n|, fixed point of Remark 3.45).",
    "friction.mu": "Coulomb friction coefficient mu_f >= 0 (> 0 for `coulomb`).",
    "friction.bound": "Tresca bound F(x, y) >= 0 on Gamma_C (formula).",
    "friction.normal_stress": "Which |sigma_n| enters the Coulomb bound: `hat-projection` "
                              "(lumped projection onto the h~ hats; F vanishes where the "
                              "body separates) or `fine-edges` ((3.123) literally).",
    "solver.method": "`auto` (the active-set method), `active-set` (semismooth Newton "
                     "condensed onto Gamma_C) or `uzawa` (Algorithms 3.38 / 3.41).",
    "solver.metric": "Metric of the projection P+ (Remark 3.40): `h12` (H^{1/2}-equivalent, "
                     "mesh-independent iteration counts) or `euclidean`.",
    "solver.rho": "Step rho of Algorithm 3.38 (dimensionless: the metric carries the "
                  "plane-strain modulus).",
    "solver.eps": "Stopping tolerance epsilon of Algorithm 3.38 (relative increment).",
    "solver.max_iter": "Largest number of iterations (Uzawa steps; Coulomb fixed-point "
                       "steps of the active-set method).",
    "solver.rho1": "Step rho_1 of the inner (lambda_n) loop of Algorithm 3.41.",
    "solver.rho2": "Step rho_2 of the nu update of Algorithm 3.41, relative to its "
                   "stability bound: 0 < rho2 < 2.",
    "solver.eps1": "Tolerance epsilon_1 of the inner loop of Algorithm 3.41.",
    "solver.eps2": "Tolerance epsilon_2 of the outer loop of Algorithm 3.41 (on nu or, "
                   "for Coulomb, on F).",
    "solver.loop_order": "`friction-outer` (Algorithm 3.41) or `contact-outer` (the loops "
                         "exchanged, Remark 3.43).",
    "solver.friction_metric": "Diagonal metric of the projection P^Lambda: `mass` (Remark "
                              "3.44) or `jacobi` (mass weighted by the diagonal of the nu "
                              "operator).",
    "solver.condensed": "Iterate Uzawa on the Gamma_C response computed once (`true`) or "
                        "solve the sparse system every step (`false`); the same iterates. "
                        "`auto`: the response for nested Uzawa, sparse solves for "
                        "Algorithm 3.38.",
    "units.length": "Unit of every length of the scene (coordinates, gap, displacements); "
                    "only the labels of plots read it. Not given: no unit is shown.",
    "units.stress": "Unit of E, tractions and stresses; only the labels of plots read it. "
                    "Not given: no unit is shown.",
    "benchmark.kind": "The analytic solution the contact pictures draw against p_h, q_h, "
                      "for the forces the solution carries: `none`, `hertz`, `flat-punch`, "
                      "`cattaneo-mindlin` (needs Coulomb friction) or `wedge`.",
    "benchmark.radius": "Radius R of the cylinder (`hertz`, `cattaneo-mindlin`).",
    "benchmark.half_width": "Half-width a of the rigid flat punch (`flat-punch`).",
    "benchmark.slope": "Slope s of the wedge's flanks, cot of its semi-angle (`wedge`).",
    "benchmark.center": "Point [x, y] of the foundation line where the analytic solution "
                        "is centred.",
    "discretisation.order": "Polynomial order k of PEERS_k (0, 1, 2): stress rows in RT_k "
                            "plus Curl bubbles, u in P_k, the rotation in P_{k+1}; 0 is the "
                            "thesis (see theory/order).",
    "discretisation.multipliers": "Family of phi, lambda_n, lambda_t: `coarse` (P1 on h~, "
                                  "order 0 only), `facet` (discontinuous P_k on the fine "
                                  "edges, lambda_n >= 0 on its Bernstein coefficients, "
                                  "frictionless) or `auto` (coarse at k = 0, facet above).",
}

# the module constant that lists the allowed values of a key
CHOICES = {
    "geometry.kind": "GEOMETRY_KINDS", "contact.ends": "CONTACT_ENDS",
    "contact.discrete_gap": "DISCRETE_GAPS",
    "friction.law": "FRICTION_LAWS", "friction.normal_stress": "NORMAL_STRESSES",
    "solver.method": "SOLVER_METHODS", "solver.metric": "METRICS",
    "solver.loop_order": "LOOP_ORDERS", "solver.friction_metric": "FRICTION_METRICS",
    "units.length": "LENGTH_UNITS", "units.stress": "STRESS_UNITS",
    "benchmark.kind": "BENCHMARK_KINDS", "discretisation.order": "ORDERS",
    "discretisation.multipliers": "MULTIPLIER_FAMILIES",
}


@dataclasses.dataclass
class SceneKey:
    """One key of a scene file."""

    key: str
    type: str
    default: str
    choices: tuple
    meaning: str


def _default(f: dataclasses.Field) -> str:
    if f.default is not dataclasses.MISSING:
        value = f.default
    elif f.default_factory is not dataclasses.MISSING:
        value = f.default_factory()
    else:
        return "required"
    if value is None:
        return "none"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, list):
        return "[" + ", ".join(f'"{v}"' if isinstance(v, str) else repr(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{}"
    return repr(value)


def _kind(key: str, annotation: str, formulas: set) -> str:
    """The type of a key as a reader of a scene file writes it."""
    kind = str(annotation).replace(" | None", ", optional")
    if key not in formulas:
        return kind
    if kind.startswith("str"):
        return "formula"
    if "dict" in kind:
        return "list of 2 formulas, or a table of them by label"
    return "list of 2 formulas"


def scene_keys() -> list[SceneKey]:
    """Every key a scene file may hold, from :mod:`ngdual.scene` (sections, dataclasses).

    A ``LookupError`` names a key without a meaning in :data:`MEANINGS`, a meaning of a
    key the code does not have, or a constant of :data:`CHOICES` that is gone.
    """
    from .. import scene

    keys = [SceneKey("name", "str", "the file name", (), MEANINGS.get("name", "")),
            SceneKey("description", "str", "none", (), MEANINGS.get("description", ""))]
    keys += [SceneKey(f"boundary.{role}", "list of str", "[]", (),
                      MEANINGS.get(f"boundary.{role}", "")) for role in scene.ROLES]
    for section, cls in scene.SECTIONS.items():
        for f in dataclasses.fields(cls):
            key = f"{section}.{f.name}"
            constant = CHOICES.get(key)
            if constant is not None and not hasattr(scene, constant):
                raise LookupError(f"scene reference: ngdual.scene.{constant} (the values of "
                                  f"{key}) is gone; update CHOICES in {__file__}")
            choices = tuple(getattr(scene, constant)) if constant else ()
            keys.append(SceneKey(key, _kind(key, f.type, scene.FORMULAS), _default(f),
                                 choices, MEANINGS.get(key, "")))
    missing = [k.key for k in keys if not k.meaning]
    unknown = sorted(set(MEANINGS) - {k.key for k in keys})
    if missing or unknown:
        raise LookupError(f"scene reference out of date with ngdual.scene: keys without a "
                          f"meaning {missing}, meanings of keys that do not exist {unknown}; "
                          f"edit MEANINGS in {__file__}")
    return keys


def _text(text: str) -> str:
    """Plain text in a Markdown table cell: its bars and stars are not syntax."""
    return re.sub(r"\s+", " ", text.replace("|", "\\|").replace("*", "\\*"))


def _meaning(text: str) -> str:
    """Text whose `code` spans (or reStructuredText ``literals``) stay code; the text
    between them is plain."""
    parts = text.replace("``", "`").split("`")
    return "".join(f"`{part}`" if i % 2 else _text(part) for i, part in enumerate(parts))


def _generated_by(source: str) -> list[str]:
    return [f"*Generated from {source} by `{COMMAND}`; a test fails when this file and the "
            f"code differ. Edit the code, not this file.*", ""]


def scene_keys_markdown() -> str:
    """The scene-key reference: one Markdown table per TOML section."""
    lines = ["# Scene keys", "", *_generated_by("`ngdual.scene`"),
             "Every key a scene file may hold, one table per TOML section; what a scene is, "
             "with an example: [Scene files](scenes.md).", ""]
    sections: dict[str, list[SceneKey]] = {}
    for key in scene_keys():
        section = f"[{key.key.split('.')[0]}]" if "." in key.key else "Top level"
        sections.setdefault(section, []).append(key)
    for section, keys in sections.items():
        lines += [f"## {section}", "", "| key | type | default | meaning |",
                  "|---|---|---|---|"]
        for k in keys:
            meaning = _meaning(k.meaning)
            if k.choices:
                meaning += " One of: " + ", ".join(f"`{c}`" for c in k.choices) + "."
            default = k.default if k.default in WORDS else f"`{k.default}`"
            lines.append(f"| `{k.key}` | {_text(k.type)} | {default} | {meaning} |")
        lines.append("")
    return "\n".join(lines)


# --- the command line ----------------------------------------------------------------------------

def _metavar(action: argparse.Action) -> str:
    if isinstance(action.metavar, tuple):
        return " ".join(action.metavar)
    if action.metavar:
        return action.metavar
    if action.choices:
        return "{" + ",".join(map(str, action.choices)) + "}"
    return action.dest.upper()


def _shown(actions: list[argparse.Action]) -> list[argparse.Action]:
    return [a for a in actions if not isinstance(a, argparse._HelpAction)
            and a.help != argparse.SUPPRESS]


def _usage(title: str, p: argparse.ArgumentParser) -> str:
    """One usage line, the same on every Python (argparse's own wraps by the terminal)."""
    words = [title]
    for action in _shown(p._actions):
        if isinstance(action, argparse._SubParsersAction):
            word = _metavar(action) + " ..."
            words.append(word if action.required else f"[{word}]")
            continue
        if not action.option_strings:
            words.append(_metavar(action))
            continue
        word = action.option_strings[0]
        if action.nargs != 0:
            word += " " + _metavar(action)
            if action.nargs in ("+", "*") or isinstance(action, argparse._AppendAction):
                word += " ..."
        words.append(word if action.required else f"[{word}]")
    return " ".join(words)


def _option_rows(p: argparse.ArgumentParser) -> list[tuple[str, str, str]]:
    rows = []
    for action in _shown(p._actions):
        if isinstance(action, argparse._SubParsersAction):
            continue
        names = ", ".join(action.option_strings) or _metavar(action)
        if action.option_strings and action.nargs != 0:
            names += " " + _metavar(action)
            if action.nargs in ("+", "*"):
                names += " ..."
        default = action.default
        if action.nargs == 0 or default in (None, argparse.SUPPRESS) or default == []:
            shown = ""
        else:
            shown = " ".join(map(str, default)) if isinstance(default, list) else str(default)
        text = action.help or ""
        if action.choices and not action.option_strings:
            text += " One of: " + ", ".join(map(str, action.choices)) + "."
        rows.append((names, shown, text))
    return rows


def _commands(title: str, p: argparse.ArgumentParser, summary: str,
              depth: int = 0) -> list[tuple[str, argparse.ArgumentParser, str, int]]:
    """``p`` and its subcommands (``ngdual bench`` has its own), depth first."""
    sub = next((a for a in p._actions if isinstance(a, argparse._SubParsersAction)), None)
    here = [(title, p, summary, depth)]
    if sub is None:
        return here
    helps = {choice.dest: choice.help for choice in sub._choices_actions}
    return here + [c for name, q in sub.choices.items()
                   for c in _commands(f"{title} {name}", q, helps.get(name) or "", depth + 1)]


def cli_commands_markdown() -> str:
    """The command-line reference: per command its usage and a table of its arguments."""
    from ..cli import parser

    top = parser()
    lines = ["# Command-line options", "", *_generated_by("`ngdual.cli.parser()`"),
             "Every subcommand of `ngdual` with its usage line and arguments; what the "
             "commands print and write, and their exit status: [Command line](cli.md).", ""]
    for title, p, summary, depth in _commands("ngdual", top, top.description or ""):
        lines += [f"{'#' * min(depth + 2, 3)} {title}", ""]
        if summary:
            summary = summary[0].upper() + summary[1:]
            lines += [_meaning(summary if summary.endswith(".") else summary + "."), ""]
        lines += ["```text", _usage(title, p), "```", ""]
        if p.epilog:
            lines += [_meaning(p.epilog[0].upper() + p.epilog[1:]) + ".", ""]
        rows = _option_rows(p)
        if rows:
            lines += ["| argument | default | meaning |", "|---|---|---|"]
            for names, default, text in rows:
                shown = f"`{default}`" if default else " "
                lines.append(f"| `{names}` | {shown} | {_meaning(text)} |")
            lines.append("")
    return "\n".join(lines)


def documents() -> dict[str, str]:
    """File name in ``docs/reference`` -> its text, as the code gives it now."""
    return {SCENE_KEYS: scene_keys_markdown(), CLI_COMMANDS: cli_commands_markdown()}


def stale(folder: Path = FOLDER) -> list[str]:
    """The files in ``folder`` that are missing or differ from :func:`documents`."""
    return [name for name, text in documents().items()
            if not (folder / name).is_file()
            or (folder / name).read_text(encoding="utf-8") != text]


def main(argv: list[str] | None = None) -> int:
    """Write the references into ``docs/reference`` (``--check``: compare only)."""
    p = argparse.ArgumentParser(prog=COMMAND, description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=FOLDER,
                   help="folder of the Markdown files (default: docs/reference of the checkout)")
    p.add_argument("--check", action="store_true",
                   help="write nothing; exit with status 1 if a file differs from the code")
    args = p.parse_args(argv)
    if args.check:
        differ = stale(args.out)
        for name in differ:
            print(f"{args.out / name} is out of date with the code: run {COMMAND}")
        return 1 if differ else 0
    if not args.out.is_dir():
        p.error(f"--out: no folder {args.out}")
    for name, text in documents().items():
        (args.out / name).write_text(text, encoding="utf-8")
        print(args.out / name)
    return 0


if __name__ == "__main__":
    sys.exit(main())
