"""A clone alone passes: no file of the repository refers to a path outside it (issue 21).

A user clones the repository into an empty folder and runs the README's commands; ``.ci/run``
does the same in a temporary folder. Whatever lies beside a developer's working tree (a folder
of notes next to the clone, a script in ``/tmp``) is missing there, so no file may refer to it. The
scan reads the packages, tests, examples, benchmarks and documentation, the README, the project
file and the CI script, line by line, and names every line that leaves the repository by:

- a relative path into the folder of notes beside it (two dots, then the folder's name; or the
  repository's parent joined with that name);
- the folder holding the repository (``REPO.parent``, ``ROOT.parents[0]``);
- ``Path(__file__)`` followed by more ``.parent`` steps than the file lies deep in the repository;
- a Markdown link whose relative target resolves outside the repository;
- an absolute path of one machine (``/tmp/...``, ``/work/...``, ``/home/...``).
"""

from __future__ import annotations

import posixpath
import re

import pytest

from tests.conftest import REPO

#: Folders scanned (all their files with a suffix of SCANNED_SUFFIXES), and single files.
SCANNED_FOLDERS = ("trajgen", "topology", "limits", "tests", "examples", "benchmarks", "docs")
SCANNED_FILES = ("README.md", "pyproject.toml", ".ci/run")
SCANNED_SUFFIXES = {".py", ".toml", ".sh", ".md", ".txt", ".cfg", ".ini", ".json", ".yml", ".yaml"}
#: Folders of generated files, never part of a clone (docs/_build is the Sphinx site).
GENERATED = {"_build", "__pycache__", ".hypothesis", ".pytest_cache", ".ruff_cache"}
#: This file, whose patterns and examples spell out what the scan looks for.
THIS_FILE = "tests/test_clone.py"

#: what the line refers to -> pattern of a line that refers to it, in any file
ESCAPES = {
    "the shared folder beside the repository": re.compile(
        r"\.\.[/\\]+shared\b|parents?\b[^\n]*/\s*[\"']shared[\"']"
    ),
    "the folder holding the repository": re.compile(r"(?i)\b\w*(?:repo|root)\w*\s*\.\s*parents?\b"),
    "an absolute path of one machine": re.compile(r"(?<![\w.:/])/(?:tmp|work|home|Users|mnt)/"),
}
#: ``Path(__file__)`` and the steps up after it: ``.parent`` repeated, or ``.parents[N]``
FILE_PARENTS = re.compile(
    r"Path\(__file__\)(?:\.resolve\(\))?(?P<steps>(?:\.parent\b)*)(?:\.parents\[(?P<n>\d+)\])?"
)
#: A Markdown link's target: ``[text](target)``, up to a fragment or a title
MARKDOWN_LINK = re.compile(r"\]\((?P<target>[^)\s#]+)")


def steps_up(match: re.Match) -> int:
    """How many folders up from the file a ``Path(__file__)`` expression goes (1: the file's folder)."""
    steps = match["steps"].count(".parent")
    return steps + (int(match["n"]) + 1 if match["n"] is not None else 0)


def leaves_the_repository(relative: str, target: str) -> bool:
    """Whether a relative link ``target`` in the file ``relative`` (POSIX, from the root) leads outside."""
    if re.match(r"[a-zA-Z][a-zA-Z0-9+.-]*:|/", target):  # a URL, mailto:, or an absolute path
        return False
    resolved = posixpath.normpath(posixpath.join(posixpath.dirname(relative), target))
    return resolved == ".." or resolved.startswith("../")


def escapes(relative: str, text: str) -> list[str]:
    """The lines of a file that refer to a path outside the repository, and what they refer to.

    Parameters
    ----------
    relative : str
        The file's path from the repository's root, with ``/`` (where it lies decides where
        ``Path(__file__)`` and relative links lead).
    text : str
        The file's text.

    Returns
    -------
    list of str
        ``"<file>:<line>: <what it refers to>: <the line>"``, one per offending line and kind.
    """
    depth = relative.count("/") + 1  # the steps up from the file that reach the repository's root
    found = []
    for number, line in enumerate(text.splitlines(), start=1):
        kinds = [what for what, pattern in ESCAPES.items() if pattern.search(line)]
        if any(steps_up(match) > depth for match in FILE_PARENTS.finditer(line)):
            kinds.append("Path(__file__) above the repository's root")
        if relative.endswith(".md") and any(
            leaves_the_repository(relative, match["target"]) for match in MARKDOWN_LINK.finditer(line)
        ):
            kinds.append("a link outside the repository")
        found += [f"{relative}:{number}: {what}: {line.strip()}" for what in kinds]
    return found


def scanned_files() -> list[str]:
    """The files the scan reads, as paths from the repository's root."""
    paths = [REPO / name for name in SCANNED_FILES]
    for folder in SCANNED_FOLDERS:
        paths += [
            path
            for path in (REPO / folder).rglob("*")
            if path.is_file()
            and path.suffix in SCANNED_SUFFIXES
            and not GENERATED.intersection(path.relative_to(REPO).parts)
        ]
    return sorted(name for path in paths if (name := path.relative_to(REPO).as_posix()) != THIS_FILE)


def test_no_file_refers_to_a_path_outside_the_repository():
    found = [line for name in scanned_files() for line in escapes(name, (REPO / name).read_text("utf-8"))]
    assert not found, "a clone alone would miss what these lines refer to:\n" + "\n".join(found)


def test_the_scan_reads_every_kind_of_file():
    names = scanned_files()
    for name in (
        ".ci/run",
        "README.md",
        "pyproject.toml",
        "docs/conf.py",
        "docs/formats/vda5050.md",
        "examples/swap.toml",
        "tests/conftest.py",
        "tests/support/vda5050_reference.py",
        "benchmarks/bench_continuity.py",
        "trajgen/export/vda5050/files.py",
        "topology/__init__.py",
        "limits/__init__.py",
    ):
        assert name in names
    assert not [name for name in names if "/_build/" in name or "__pycache__" in name]


#: The folder of notes beside a developer's clone, as the lines below would name it.
UP = ".." + "/"
#: That folder's name, kept out of the lines of this file that the scan itself reads.
NOTES = "sha" + "red"
#: case -> (file, line, what the scan must say it refers to)
OUTSIDE = {
    "shared-beside-the-repo": (
        "tests/t.py",
        f'SCHEMAS = REPO.parent / "{NOTES}" / "vda5050"',
        "shared folder",
    ),
    "repo-parent": ("tests/t.py", 'SCHEMAS = REPO.parent / "other"', "folder holding the repository"),
    "root-parents": ("docs/conf.py", "sys.path.insert(0, str(ROOT.parents[0]))", "folder holding"),
    "relative-shared": ("README.md", f"jsonschema {UP}shared/order.schema order.json", "shared folder"),
    "windows-shared": ("benchmarks/b.py", 'open(r"..\\' + NOTES + '\\order.schema")', "shared folder"),
    "file-three-up": ("tests/t.py", "HERE = Path(__file__).resolve().parent.parent.parent", "Path(__file__)"),
    "file-parents-index": ("examples/e.py", "Path(__file__).parents[2]", "Path(__file__)"),
    "deep-file-too-far": ("trajgen/export/x.py", "Path(__file__).parents[3]", "Path(__file__)"),
    "markdown-link": ("docs/formats/x.md", f"see [the schema](../../{UP}shared/order.schema)", "a link"),
    "readme-link": ("README.md", f"[the algorithm]({UP}shared/ALGORITHM.md)", "shared folder"),
    "tmp-script": ("tests/t.py", "``/tmp/s13/continuity.py``, which prints", "absolute path"),
    "work-folder": ("benchmarks/b.py", f"DATA = Path('/work/{NOTES}/data')", "absolute path"),
}


@pytest.mark.parametrize(("relative", "line", "what"), OUTSIDE.values(), ids=list(OUTSIDE))
def test_the_scan_finds_a_path_outside(relative, line, what):
    found = escapes(relative, f"first line\n{line}\n")
    assert found, line
    assert all(entry.startswith(f"{relative}:2: ") and entry.endswith(line.strip()) for entry in found)
    assert any(what in entry for entry in found), found


#: case -> (file, line) that stays inside the repository
INSIDE = {
    "repo-root": ("tests/conftest.py", "REPO = Path(__file__).resolve().parent.parent"),
    "benchmark-root": ("benchmarks/b.py", "sys.path.insert(0, str(Path(__file__).resolve().parent.parent))"),
    "deep-file-root": ("trajgen/export/x.py", "ROOT = Path(__file__).parents[2]"),
    "example-folder": ("examples/e.py", "here = Path(__file__).resolve().parent"),
    "sibling-page": ("docs/formats/generic-csv.md", "the [scenario](../scenario.md) of the run"),
    "url": ("docs/x.md", "[VDA 5050](https://github.com/VDA5050/VDA5050/tree/main/home/x)"),
    "hostile-input": ("tests/t.py", 'write_profiles(verified, ("../x", "/abs/y"), tmp_path)'),
    "a-path-parent": ("trajgen/x.py", "key = (os.path.realpath(path.parent), path.name)"),
    "shared-as-a-word": ("topology/x.py", "on a shared leg the vehicle nearer the junction"),
}


@pytest.mark.parametrize(("relative", "line"), INSIDE.values(), ids=list(INSIDE))
def test_the_scan_passes_what_stays_inside(relative, line):
    assert escapes(relative, line) == []


def test_the_packages_cite_only_documents_of_the_repository():
    """A docstring or comment that cites a document (``docs/planner.md``) names one a clone has."""
    cited = re.compile(r"(?<![\w/.-])((?:docs/)?[\w.-]+\.md)\b")
    missing = []
    for package in ("trajgen", "topology", "limits"):
        for source in sorted((REPO / package).rglob("*.py")):
            for number, line in enumerate(source.read_text(encoding="utf-8").splitlines(), 1):
                for name in cited.findall(line):
                    if not (REPO / name).is_file() and not (REPO / "docs" / name).is_file():
                        missing.append(f"{source.relative_to(REPO)}:{number}: {name}")
    assert missing == []
