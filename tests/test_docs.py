"""The documentation site builds without a warning, reaches every page, and its examples run.

The build is the one CI needs: ``python -m sphinx -W --keep-going -n -b html docs OUT``: nitpicky,
so a reference to a page, heading or Python object that does not exist fails it. A tiny copy of
the site with one planted defect shows that each kind of defect does fail it. The ``python`` code
blocks of every page run (``>>>`` examples must print what they show); fence a fragment that cannot
run as ``text``.
"""

from __future__ import annotations

import doctest
import pickle
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO

pytestmark = pytest.mark.slow

DOCS = REPO / "docs"
PAGES = sorted([*DOCS.glob("*.md"), *(DOCS / "formats").glob("*.md")])


def _sphinx(source: Path, out: Path) -> subprocess.CompletedProcess:
    command = [
        sys.executable,
        "-m",
        "sphinx",
        "-W",
        "--keep-going",
        "-n",
        "-b",
        "html",
        str(source),
        str(out),
    ]
    return subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> tuple[subprocess.CompletedProcess, Path]:
    out = tmp_path_factory.mktemp("docs") / "html"
    return _sphinx(DOCS, out), out


def test_the_docs_build_with_no_warning_and_no_broken_reference(built):
    result, out = built
    assert result.returncode == 0, result.stdout + result.stderr
    assert (out / "index.html").is_file()


def test_every_page_is_reachable_from_the_root_toctree(built):
    result, out = built
    with (out / ".doctrees" / "environment.pickle").open("rb") as stream:
        env = pickle.load(stream)  # written by the build above, in this test's temporary folder
    reachable, todo = set(), [env.config.root_doc]
    while todo:
        page = todo.pop()
        if page not in reachable:
            reachable.add(page)
            todo += env.toctree_includes.get(page, [])
    pages = {page.relative_to(DOCS).with_suffix("").as_posix() for page in PAGES}
    assert {"index", "planner", "timing", "verifier", "scenario", "cli", "online", "api"} <= pages
    assert {"formats/index", "formats/generic-csv"} <= pages
    assert pages - reachable == set(), result.stdout + result.stderr
    for page in pages:
        assert (out / f"{page}.html").is_file(), page


def test_the_command_line_page_has_the_help_of_every_command(built):
    from trajgen.cli import command_parsers

    _, out = built
    text = (out / "cli.html").read_text(encoding="utf-8")
    commands = command_parsers()
    assert len(commands) >= 5
    for name in commands:
        assert f'id="command-{name}"' in text
        assert f"usage: trajgen {name}" in text


#: Pages with one defect each, built together: the build must fail and name every defect.
_DEFECTS = [
    pytest.param("See [a page](missing.md).\n", "missing.md", id="link-to-a-missing-page"),
    pytest.param("See [a heading](clean.md#no-such-heading).\n", "no-such-heading", id="missing-heading"),
    pytest.param("See {py:func}`trajgen.no_such_function`.\n", "no_such_function", id="missing-object"),
    pytest.param("See {py:class}`topology.Routes`.\n", "topology.Routes", id="misspelt-class"),
]


def _tiny_site(root: Path, pages: dict[str, str], *, orphans: tuple[str, ...] = ()) -> Path:
    """A docs folder with our ``conf.py``, an index listing ``pages`` and pages outside every toctree."""
    source = root / "docs"
    source.mkdir()
    shutil.copy(DOCS / "conf.py", source / "conf.py")
    listed = "\n".join(pages)
    (source / "index.md").write_text(f"# Tiny\n\n```{{toctree}}\n{listed}\n```\n", encoding="utf-8")
    for name, body in pages.items():
        (source / f"{name}.md").write_text(f"# {name.title()}\n\n## A heading\n\n{body}", encoding="utf-8")
    for name in orphans:
        (source / f"{name}.md").write_text(f"# {name.title()}\n", encoding="utf-8")
    return source


@pytest.fixture(scope="module")
def defective(tmp_path_factory) -> str:
    """The output of one build of a site with every defect of :data:`_DEFECTS` and an orphan page."""
    root = tmp_path_factory.mktemp("defects")
    pages = {"clean": "Nothing wrong here.\n"}
    pages |= {f"defect{k}": param.values[0] for k, param in enumerate(_DEFECTS)}
    result = _sphinx(_tiny_site(root, pages, orphans=("orphan",)), root / "html")
    output = result.stdout + result.stderr
    assert result.returncode != 0, output
    return output


def test_a_site_without_defects_builds(tmp_path):
    pages = {"clean": "See [the other page](other.md) and [its heading](other.md#a-heading).\n"}
    result = _sphinx(_tiny_site(tmp_path, pages | {"other": "Text.\n"}), tmp_path / "html")
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize(("page", "defect"), _DEFECTS)
def test_a_broken_reference_fails_the_build_naming_it(defective, page, defect):
    assert defect in defective, defective


def test_a_page_outside_every_toctree_fails_the_build(defective):
    assert "orphan" in defective, defective


def _python_blocks(page: Path) -> list[str]:
    """The ``python`` code blocks of a page."""
    return re.findall(r"^```python\n(.*?)^```", page.read_text(encoding="utf-8"), flags=re.S | re.M)


@pytest.mark.parametrize("page", [p for p in PAGES if _python_blocks(p)], ids=lambda p: p.name)
def test_the_python_of_a_page_runs_and_prints_what_it_says(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # in case an example writes files
    parser, runner = doctest.DocTestParser(), doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for number, block in enumerate(_python_blocks(page)):
        name = f"{page.name}[{number}]"
        if ">>>" in block:  # an interactive example: its output is checked
            runner.run(parser.get_doctest(block, {}, name, str(page), 0))
        else:  # a script: it runs
            exec(compile(block, name, "exec"), {})  # our own documentation's example
    assert runner.summarize(verbose=False).failed == 0


def test_every_page_has_a_python_example_that_the_suite_runs():
    without = [page.relative_to(DOCS).as_posix() for page in PAGES if not _python_blocks(page)]
    assert without == [], f"pages without a ```python example: {without}"
