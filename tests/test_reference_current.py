"""The scene-key and command-line references in the checkout are what the code writes.

``docs/reference/scene-keys.md`` and ``docs/reference/cli-commands.md`` are Markdown files a
reader opens in the checkout (and the documentation site shows); they are written from the
code by ``python -m ngdual.studies.reference``. These tests write them again in memory and
fail, naming that command, when a checked-in file differs; and they check that what the
files list is what the validator and the parser accept.
"""

from __future__ import annotations

import difflib
import re

import pytest

from ngdual.studies import reference

KEY_ROW = re.compile(r"^\| `([^`]+)` \|", flags=re.M)


@pytest.mark.parametrize("name", [reference.SCENE_KEYS, reference.CLI_COMMANDS])
def test_the_checked_in_reference_is_what_the_code_writes(name):
    path = reference.FOLDER / name
    expected = reference.documents()[name]
    found = path.read_text(encoding="utf-8") if path.is_file() else ""
    if found != expected:
        diff = "".join(difflib.unified_diff(found.splitlines(True), expected.splitlines(True),
                                            "checked in", "from the code", n=1))
        pytest.fail(f"docs/reference/{name} is out of date with the code; regenerate it with "
                    f"`{reference.COMMAND}` and commit it:\n{diff[:4000]}")


def validator_keys() -> set[str]:
    """The keys ngdual.scene accepts, as its own error messages name them."""
    from ngdual.scene import SceneError, scene_from_dict

    def known(document: dict, field: str, after: str) -> list[str]:
        with pytest.raises(SceneError) as err:
            scene_from_dict(document)
        message = dict(err.value.problems)[field]
        return [k.strip() for k in message.split(after, 1)[1].split(",")]

    base = {"geometry": {"kind": "thesis-3.46"}, "boundary": {"dirichlet": ["left"]}}
    sections = known({**base, "zzz": {}}, "zzz", "sections are ")
    keys = {s for s in sections if s in ("name", "description")}
    keys |= {f"boundary.{role}" for role in
             known({**base, "boundary": {"zzz": []}}, "boundary.zzz", "use one of ")}
    for section in set(sections) - {"name", "description", "boundary"}:
        table = dict(base.get(section, {}), zzz=1)
        keys |= {f"{section}.{key}" for key in
                 known({**base, section: table}, f"{section}.zzz", "known keys: ")}
    return keys


def test_the_scene_key_reference_lists_exactly_the_keys_the_validator_accepts():
    listed = KEY_ROW.findall(reference.scene_keys_markdown())
    assert len(listed) == len(set(listed))
    assert set(listed) == validator_keys()


def test_every_scene_key_with_a_fixed_set_of_values_lists_them():
    text = reference.scene_keys_markdown()
    row = next(line for line in text.splitlines() if line.startswith("| `friction.law` |"))
    assert "One of: `none`, `tresca`, `coulomb`." in row
    assert "| `\"none\"` |" in row                       # the default, from the dataclass


def test_the_cli_reference_lists_every_subcommand_and_option():
    from ngdual.cli import parser

    text = reference.cli_commands_markdown()
    subcommands = next(a for a in parser()._actions if a.dest == "command").choices
    for name, sub in subcommands.items():
        assert f"## ngdual {name}\n" in text, name
        for action in sub._actions:
            if action.help == "==SUPPRESS==" or "--help" in action.option_strings:
                continue
            for flag in action.option_strings:
                assert f"| `{flag}" in text.split(f"## ngdual {name}\n", 1)[1], (name, flag)


def test_the_generator_writes_the_files_and_check_names_the_command(tmp_path, capsys):
    assert reference.main(["--out", str(tmp_path)]) == 0
    assert reference.main(["--out", str(tmp_path), "--check"]) == 0
    capsys.readouterr()
    (tmp_path / reference.CLI_COMMANDS).write_text("# edited by hand\n", encoding="utf-8")
    assert reference.main(["--out", str(tmp_path), "--check"]) == 1
    out = capsys.readouterr().out
    assert reference.CLI_COMMANDS in out and reference.COMMAND in out
    assert reference.SCENE_KEYS not in out
