"""The repository holds sources, not dumps: no tracked file over 1 MB outside the test data and images.

A 139 MB gdb core dump and a 7.4 MB CasADi dump were once committed by accident (issue 49, item 6):
a fresh clone weighed 156 MB. ``.gitignore`` keeps ``core``, ``core.*`` and ``*.casadi`` out; this
test catches any other large file before it lands.
"""

from __future__ import annotations

import shutil
import subprocess

import pytest

from tests.conftest import REPO

pytestmark = pytest.mark.slow

#: The largest tracked file allowed outside the folders of data, bytes.
MAX_BYTES = 1_000_000
#: Folders whose files may be larger: stored reference data, the documentation's pictures.
DATA_FOLDERS = ("tests/data/", "docs/images/")


def _tracked() -> list[str]:
    if shutil.which("git") is None or not (REPO / ".git").exists():
        pytest.skip("not a git checkout (an sdist or a copy): nothing is tracked")
    listed = subprocess.run(
        ["git", "ls-files", "-z"], cwd=REPO, capture_output=True, check=True, timeout=60
    ).stdout.decode()
    return [name for name in listed.split("\0") if name]


def test_no_tracked_file_is_over_a_megabyte_outside_the_data_folders():
    large = {
        name: (REPO / name).stat().st_size
        for name in _tracked()
        if not name.startswith(DATA_FOLDERS)
        and (REPO / name).is_file()
        and (REPO / name).stat().st_size > MAX_BYTES
    }
    assert large == {}, f"tracked files over {MAX_BYTES:,} bytes: {large} (dumps belong in .gitignore)"


def test_the_tracked_files_total_under_ten_megabytes():
    total = sum((REPO / name).stat().st_size for name in _tracked() if (REPO / name).is_file())
    assert total < 10_000_000, f"{total:,} bytes tracked"


def test_dumps_are_ignored():
    _tracked()  # a git checkout, or skipped
    for name in ("core", "core.1234", "nlp_hess_l.casadi"):
        ignored = subprocess.run(["git", "check-ignore", "-q", name], cwd=REPO, timeout=60)
        assert ignored.returncode == 0, name
