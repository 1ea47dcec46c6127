"""Golden files: every dialect and unit setting renders, byte for byte, what the per-value formatter wrote.

The cases and the stored files are those of :mod:`tests.support.golden_profiles`; a long schedule is compared
by SHA-256 digest.
"""

from __future__ import annotations

import pytest

from tests.support.golden_profiles import (
    CASES,
    GOLDEN,
    LONG_DIGESTS,
    first_difference,
    long_swap,
    profile_digests,
)
from trajgen.export.csv import CsvOptions


@pytest.mark.parametrize("case", CASES, ids=[case.name for case in CASES])
def test_the_files_are_byte_identical_to_the_golden_files(case):
    rendered = case.render()
    folder = GOLDEN / case.name
    assert sorted(rendered) == sorted(path.name for path in folder.iterdir())
    for name, data in rendered.items():
        problem = first_difference((folder / name).read_bytes(), data)
        assert problem is None, f"{case.name}/{name}: {problem}"


def test_every_golden_folder_belongs_to_a_case():
    assert sorted(path.name for path in GOLDEN.iterdir()) == sorted(case.name for case in CASES)


@pytest.mark.parametrize(
    ("expected", "actual", "message"),
    [
        pytest.param(b"a\r\nb\r\n", b"a\r\nb\r\n", None, id="equal"),
        pytest.param(
            b"t\r\n1.5\r\n2.5\r\n",
            b"t\r\n1.5\r\n2.4\r\n",
            "line 3 differs: expected b'2.5\\r\\n', got b'2.4\\r\\n'",
            id="a-value",
        ),
        pytest.param(
            b"a\r\nb\r\n", b"a\r\nb\n", "line 2 differs: expected b'b\\r\\n', got b'b\\n'", id="a-lost-cr"
        ),
        pytest.param(
            b"a\r\nb\r\n",
            b"a\r\n",
            "the files agree on 1 lines, then the expected one has 1 more and the rendered one 0 more",
            id="a-missing-line",
        ),
    ],
)
def test_first_difference_names_the_first_differing_line(expected, actual, message):
    assert first_difference(expected, actual) == message


@pytest.mark.parametrize("length", sorted(LONG_DIGESTS), ids=[f"legs-{n:g}m" for n in sorted(LONG_DIGESTS)])
def test_a_long_schedule_hashes_to_the_golden_digests(length):
    duration, digests = LONG_DIGESTS[length]
    verified = long_swap(length)
    # a different duration means the schedule changed, not its formatting
    assert verified.schedule.duration == duration
    assert profile_digests(verified, CsvOptions()) == digests


#: VDA 5050 exports stored before the orders were built from the vda5050-sdk models (issue 36).
VDA5050_GOLDEN = GOLDEN.parent / "golden-vda5050"
VDA5050_START = "2026-05-01T08:00:00Z"


@pytest.mark.parametrize("case", ["swap-exact", "crossing-toppra"])
def test_the_vda5050_export_is_byte_identical_to_its_golden_files(case, tmp_path):
    from tests.conftest import REPO
    from trajgen.cli import main

    scenario, method = case.split("-")
    out = tmp_path / case
    options = ["--method", method, "--start-time", VDA5050_START, "--out", str(out)]
    status = main(["export-vda5050", str(REPO / "examples" / f"{scenario}.toml"), *options])
    assert status == 0
    stored = VDA5050_GOLDEN / case
    names = sorted(p.relative_to(stored).as_posix() for p in stored.rglob("*.json"))
    assert names == sorted(p.relative_to(out).as_posix() for p in out.rglob("*.json"))
    for name in names:
        problem = first_difference((stored / name).read_bytes(), (out / name).read_bytes())
        assert problem is None, f"{case}/{name}: {problem}"
