"""The documentation site builds, and a real browser shows it as a reader would see it.

The site is built once per run in quick mode (``NGDUAL_DOCS_QUICK=1``: the tutorials run on
their coarse settings) with warnings as errors, from a fresh Sphinx environment, into
``docs/_build/html`` (the documented command). Then the built pages are checked as files
(every tutorial page holds its executed outputs and a figure, the API reference lists every
public name, the scene-key and command-line pages show every key and option) and, served
on localhost, opened in headless Chromium: the mathematics is typeset by MathJax, every
image loads, the console shows no error and nothing is fetched from outside the site.
Screenshots of the home page and of the first tutorial go to ``docs/_build/screenshots``.

Without Sphinx (the ``docs`` extra) or Chromium (``apt-get install chromium
chromium-driver``) the tests are skipped on a developer's machine and fail in CI.
``NGDUAL_DOCS_REUSE_BUILD=1`` checks the site already built in ``docs/_build/html``.
"""

from __future__ import annotations

import functools
import http.server
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # a Sphinx build executing every tutorial, then Chromium

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
HTML = DOCS / "_build" / "html"
SCREENSHOTS = DOCS / "_build" / "screenshots"
BUILD_TIMEOUT_S = 1800
CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                  "--no-first-run", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync",
                  "--disable-dev-shm-usage", "--window-size=1400,1600")


def missing(what: str, how: str):
    """Fail in CI (where the site must be tested), skip elsewhere."""
    message = f"{what} is not installed ({how})"
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)


def executable(*names: str) -> str | None:
    return next((path for path in map(shutil.which, names) if path), None)


@pytest.fixture(scope="module")
def site() -> Path:
    """The site, built in quick mode with warnings as errors (``NGDUAL_DOCS_REUSE_BUILD=1``:
    the one already in docs/_build/html, built by the documented command)."""
    if os.environ.get("NGDUAL_DOCS_REUSE_BUILD") == "1" and (HTML / "index.html").is_file():
        return HTML
    for module in ("sphinx", "myst_nb", "pydata_sphinx_theme", "numpydoc"):
        if importlib.util.find_spec(module) is None:
            missing(module, 'pip install -e ".[docs]"')
    env = dict(os.environ, NGDUAL_DOCS_QUICK="1")
    env.pop("NGDUAL_DOCS_TUTORIALS", None)
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-q", "-b", "html",
               str(DOCS), str(HTML)]
    result = subprocess.run(command, cwd=ROOT, env=env, capture_output=True, text=True,
                            timeout=BUILD_TIMEOUT_S)
    log = "\n".join(line for line in (result.stdout + result.stderr).splitlines()
                    if "[IPKernelApp]" not in line)
    assert result.returncode == 0, log[-8000:]
    return HTML


def page(site: Path, name: str) -> str:
    return (site / name).read_text(encoding="utf-8")


def tutorial_pages(site: Path) -> list[Path]:
    return sorted((site / "tutorials").glob("[0-9][0-9]_*.html"))


# --- the built files -----------------------------------------------------------------------------

def test_every_tutorial_is_a_page_with_executed_outputs_and_a_figure(site):
    sources = sorted(p.stem for p in (ROOT / "tutorials").glob("[0-9][0-9]_*.py"))
    pages = tutorial_pages(site)
    assert [p.stem for p in pages] == sources
    for path in pages:
        html = path.read_text(encoding="utf-8")
        outputs = re.findall(r'class="cell_output[^"]*"', html)
        assert len(outputs) >= 3, path.name
        assert re.search(r'<img[^>]+src="\.\./_images/[^"]+\.png"', html), path.name
        assert "Traceback" not in html, path.name
        assert "WebGuiWidget" not in html, path.name    # no placeholder of the webgui view


def test_the_api_reference_lists_every_public_name_with_its_docstring(site):
    import ngdual

    html = page(site, "reference/api.html")
    for name in ngdual.__all__:
        if name == "__version__":
            continue
        match = re.search(rf'<dt class="sig sig-object py" id="ngdual\.{name}">(.*?)</dd>',
                          html, flags=re.S)
        assert match, f"ngdual.{name} is not in the API reference"
        first_line = re.sub(r":\w+:", "", getattr(ngdual, name).__doc__.strip().splitlines()[0])
        words = re.findall(r"[A-Za-z]{4,}", first_line)[:3]
        text = re.sub(r"<[^>]+>", "", match.group(1))
        assert all(word in text for word in words), (name, words)


def test_the_scene_key_page_shows_every_key_of_its_markdown(site):
    """The keys of docs/reference/scene-keys.md (tests/test_reference_current.py checks them
    against the validator) are on the page, each as code."""
    source = (DOCS / "reference" / "scene-keys.md").read_text(encoding="utf-8")
    keys = re.findall(r"^\| `([^`]+)` \|", source, flags=re.M)
    html = page(site, "reference/scene-keys.html")
    assert len(keys) > 40
    missing = [key for key in keys if f'<span class="pre">{key}</span>' not in html]
    assert not missing, missing


def test_the_cli_reference_lists_every_subcommand_and_option(site):
    from ngdual.cli import parser

    html = re.sub(r"<[^>]+>", "", page(site, "reference/cli-commands.html"))
    subcommands = next(a for a in parser()._actions if a.dest == "command").choices
    for name, sub in subcommands.items():
        assert f"ngdual {name}" in html, name
        for action in sub._actions:
            if action.help == "==SUPPRESS==" or "--help" in action.option_strings:
                continue
            for flag in action.option_strings:
                assert flag in html, (name, flag)


def test_the_site_loads_nothing_from_outside(site):
    """No CDN: every script, stylesheet and image a page names is a file of the site."""
    for path in [site / "index.html", *tutorial_pages(site)[:1], site / "theory/model.html"]:
        html = path.read_text(encoding="utf-8")
        external = re.findall(r'<(?:script|link|img|iframe)[^>]+(?:src|href)="((?:https?:)?//'
                              r'[^"]+)"', html)
        assert not external, (path.name, external)


# --- in a browser --------------------------------------------------------------------------------

class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


@pytest.fixture(scope="module")
def server(site):
    handler = functools.partial(_QuietHandler, directory=str(site))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()
    httpd.server_close()


@pytest.fixture(scope="module")
def browser(server):
    chromium = executable("chromium", "chromium-browser", "google-chrome")
    driver_path = executable("chromedriver")
    if chromium is None or driver_path is None:
        missing("chromium and chromedriver", "apt-get install chromium chromium-driver")
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        missing("selenium", 'pip install -e ".[docs]"')
    os.environ["SE_OFFLINE"] = "true"      # Selenium Manager must not look for drivers online
    profile = tempfile.mkdtemp(prefix="ngdual-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for flag in (*CHROMIUM_FLAGS, f"--user-data-dir={profile}"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(executable_path=driver_path), options=options)
    driver.set_page_load_timeout(60)
    driver.set_script_timeout(60)
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


WAIT_FOR_MATHJAX = """
const done = arguments[arguments.length - 1];
const start = Date.now();
(function poll() {
  if (!document.querySelector('script[src*="MathJax.js"]')) {
    done({sources: 0, typeset: 0, errors: 0});    // a page without mathematics
  } else if (window.MathJax && MathJax.Hub && MathJax.isReady) {
    MathJax.Hub.Queue(function () {
      done({
        sources: document.querySelectorAll('script[type^="math/tex"]').length,
        typeset: document.querySelectorAll('.MathJax_CHTML').length,
        errors: document.querySelectorAll('.mjx-merror, .MathJax_Error').length
      });
    });
  } else if (Date.now() - start > 30000) {
    done({error: 'MathJax did not start'});
  } else {
    setTimeout(poll, 100);
  }
})();
"""

IMAGES = """
window.scrollTo(0, document.body.scrollHeight);
return Array.from(document.images).map(img => ({src: img.src, complete: img.complete,
                                                 width: img.naturalWidth}));
"""

RESOURCES = "return performance.getEntriesByType('resource').map(e => e.name);"


def open_page(browser, server: str, path: str, screenshot: str | None = None) -> dict:
    """Load a page; wait for MathJax and the images; return what the checks need."""
    browser.get_log("browser")                                  # forget earlier pages
    browser.get(f"{server}/{path}")
    math = browser.execute_async_script(WAIT_FOR_MATHJAX)
    browser.execute_async_script("""
        const done = arguments[arguments.length - 1];
        Promise.all(Array.from(document.images).map(img => img.complete ? null :
            new Promise(r => { img.onload = img.onerror = r; }))).then(() => done(true));""")
    images = browser.execute_script(IMAGES)
    if screenshot:
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        browser.execute_script("window.scrollTo(0, 0);")
        browser.save_screenshot(str(SCREENSHOTS / f"{screenshot}.png"))
        if browser.execute_script("""const img = document.querySelector('.cell_output img');
            if (img) { img.scrollIntoView({block: 'center'}); } return !!img;"""):
            browser.save_screenshot(str(SCREENSHOTS / f"{screenshot}-first-figure.png"))
    return {"math": math, "images": images, "resources": browser.execute_script(RESOURCES),
            "console": [e for e in browser.get_log("browser") if e["level"] == "SEVERE"],
            "title": browser.title}


def assert_reads_well(result: dict, server: str, min_math: int, min_images: int) -> None:
    math = result["math"]
    assert "error" not in math, math
    assert math["sources"] >= min_math, math
    assert math["typeset"] >= math["sources"] and math["errors"] == 0, math
    assert len(result["images"]) >= min_images, result["images"]
    broken = [img["src"] for img in result["images"]
              if not img["complete"] or img["width"] == 0]
    assert not broken, broken
    assert not result["console"], result["console"]
    outside = [url for url in result["resources"] if not url.startswith(server)]
    assert not outside, outside


def test_home_page_in_a_browser(browser, server):
    result = open_page(browser, server, "index.html", "home")
    assert "ngdual" in result["title"]
    assert_reads_well(result, server, min_math=4, min_images=4)
    assert (SCREENSHOTS / "home.png").stat().st_size > 10_000


def test_theory_page_has_numbered_equations_typeset(browser, server):
    result = open_page(browser, server, "theory/formulation.html")
    assert_reads_well(result, server, min_math=20, min_images=0)
    text = browser.find_element("css selector", "article").text
    for number in ("(3.12)", "(3.24)", "(3.41)"):
        assert number in text, number


def test_a_tutorial_page_in_a_browser(browser, server, site):
    first = tutorial_pages(site)[0]
    result = open_page(browser, server, f"tutorials/{first.name}", "tutorial")
    assert_reads_well(result, server, min_math=20, min_images=1)
    for name in ("tutorial.png", "tutorial-first-figure.png"):
        assert (SCREENSHOTS / name).stat().st_size > 10_000, name


def test_every_tutorial_page_has_its_mathematics_typeset(browser, server, site):
    """The markdown cells write LaTeX: MathJax typesets all of it, without an error."""
    for path in tutorial_pages(site):
        result = open_page(browser, server, f"tutorials/{path.name}")
        try:
            assert_reads_well(result, server, min_math=20, min_images=1)
        except AssertionError as err:
            raise AssertionError(f"{path.name}: {err}") from None
