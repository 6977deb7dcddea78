"""``ngdual show SCENE`` draws the geometry, its boundary labels and the initial mesh into a PNG
without solving; ``ngdual scenes`` lists every shipped scene with its description."""

import pytest

from ngdual.cli import main
from ngdual.scene import read_toml, shipped_scenes

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_show_writes_the_geometry_as_a_png_and_prints_its_path(tmp_path, capsys):
    assert main(["show", "hertz-cylinder", "--out", str(tmp_path)]) == 0
    picture = tmp_path / "geometry.png"
    assert capsys.readouterr().out.strip() == f"wrote {picture}"
    assert picture.read_bytes()[:8] == PNG_SIGNATURE
    assert not (tmp_path / "result.json").exists()                         # nothing solved


def test_show_takes_a_level_and_overrides_and_writes_nothing_for_a_bad_one(tmp_path, capsys):
    assert main(["show", "punch-on-foundation", "--level", "2", "--set", "geometry.maxh=0.5",
                 "--out", str(tmp_path / "ok")]) == 0
    assert (tmp_path / "ok" / "geometry.png").is_file()
    capsys.readouterr()
    assert main(["show", "punch-on-foundation", "--level", "0", "--out",
                 str(tmp_path / "bad")]) == 2
    assert capsys.readouterr().err.startswith("ngdual: error: --level:")
    assert not (tmp_path / "bad").exists()


@pytest.fixture(scope="module")
def listing():
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["scenes"]) == 0
    return out.getvalue()


def test_scenes_shows_each_description_in_short_wrapped_lines(listing):
    lines = listing.splitlines()
    assert max(len(line) for line in lines) <= 90
    flat = " ".join(line.strip() for line in lines)
    for name in shipped_scenes():
        assert flat.count(name) >= 1
        assert read_toml(name)[1]["description"] in flat                    # the whole of it


def test_scenes_does_not_print_a_gap_formula(listing):
    assert "ifpos(-x, abs(x + 2)" not in listing and "gap=" not in listing
