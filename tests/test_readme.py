"""The README is a short landing page whose Python example runs and whose links resolve.

The example runs verbatim and says what it computes; every file the README links to (the docs
pages, the picture) is in the repository.
"""

from __future__ import annotations

import re

import pytest

from tests.conftest import REPO
from tests.support.helpers import RUN_FILES

pytestmark = pytest.mark.slow


def _python_block() -> str:
    """The README's first ``python`` block."""
    text = (REPO / "README.md").read_text(encoding="utf-8")
    begin = text.index("```python\n") + len("```python\n")
    return text[begin : text.index("```", begin)]


def test_readme_python_example_runs_and_its_comments_hold(tmp_path, monkeypatch):
    from trajgen import Exact, Instruction

    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(_python_block(), "README.md", "exec"), namespace)  # our own README, verbatim
    route, schedule, limits = namespace["route"], namespace["schedule"], namespace["limits"]
    assert route.instruction is Instruction.COUNTERCLOCKWISE
    assert [str(r) for r in route.regions] == ["Q(A,B)", "Q(A,C)", "Q(B,C)", "Q(B,A)"]
    assert schedule.duration == pytest.approx(25.5, abs=0.05)
    assert Exact().schedule(route, limits).duration == pytest.approx(73.5)
    assert schedule.fallback_reason is None
    assert namespace["verified"].report.passed
    assert (tmp_path / "out" / "agv1.csv").is_file()
    assert (tmp_path / "out" / "agv2.csv").is_file()
    assert namespace["result"].summary()["duration_s"] == pytest.approx(27.51, abs=0.01)
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == RUN_FILES


def test_readme_python_section_needs_at_most_two_import_lines():
    import ast

    tree = ast.parse(_python_block())
    imports = [node for node in tree.body if isinstance(node, (ast.Import, ast.ImportFrom))]
    assert 1 <= len(imports) <= 2


def test_readme_is_a_landing_page_whose_links_all_resolve():
    text = (REPO / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 150  # the rest lives in docs/
    targets = {m.group(1) for m in re.finditer(r"\]\(([^)\s#]+)(?:#[^)]*)?\)", text)}
    local = {t for t in targets if not re.match(r"[a-zA-Z][a-zA-Z0-9+.-]*:", t)}
    assert {"docs/cli.md", "docs/api.md", "docs/layout.md", "docs/upgrading.md"} <= local
    for target in sorted(local):
        assert (REPO / target).is_file(), target
    pictures = [t for t in local if t.endswith(".png")]
    assert len(pictures) == 1
    assert (REPO / pictures[0]).stat().st_size < 300_000
