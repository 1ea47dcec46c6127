"""Every entry of every float array of a schedule corrupted: refused by name, or nothing exported changes.

Run from the repository root: ``python benchmarks/bench_corruption.py [--period 0.05]``.
The test suite (``tests/test_corruption.py``) corrupts one seeded entry per array
and corruption; this sweep corrupts every entry (every adjacent pair for swaps)
of every float array reachable from the exact, toppra and optimal schedules of
the swap and the crossing, and prints, per schedule, how many corruptions verify
refused naming the array, refused without naming it, left the exported CSV
unchanged, or let through with a changed CSV (the last two columns must be 0).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))  # the tests' helpers

from tests.support.corruption import corrupted, float_arrays, names  # noqa: E402
from trajgen import Exact, Optimal, Toppra, certify, load_scenario  # noqa: E402
from trajgen.errors import VerificationError  # noqa: E402
from trajgen.export.csv import CsvOptions, render_profile  # noqa: E402
from trajgen.progress import progress  # noqa: E402

SCENARIOS = {"swap": REPO / "examples" / "swap.toml", "crossing": REPO / "examples" / "crossing.toml"}


def every_corruption(array: np.ndarray):
    """(kind, corrupted array): every entry NaN, +inf, -inf, moved by 1e-3; every adjacent pair swapped."""
    flat = array.reshape(-1)
    for k in range(flat.size):
        for kind, value in (("nan", np.nan), ("+inf", np.inf), ("-inf", -np.inf)):
            bad = flat.copy()
            bad[k] = value
            yield kind, bad.reshape(array.shape)
        if flat[k] != 0.0:
            bad = flat.copy()
            bad[k] += 1e-3 * bad[k]
            yield "move", bad.reshape(array.shape)
    rows = array.reshape(array.shape[0], -1)
    for k in range(rows.shape[0] - 1):
        if np.any(rows[k] != rows[k + 1]):
            bad = rows.copy()
            bad[[k, k + 1]] = bad[[k + 1, k]]
            yield "swap", bad.reshape(array.shape)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--period", type=float, default=0.05, help="CSV sample period compared, seconds")
    args = parser.parse_args()
    options = CsvOptions(sample_period=args.period)
    methods = {"exact": Exact(), "toppra": Toppra(), "optimal": Optimal()}

    def exported(schedule):
        verified = certify(schedule)
        return render_profile(verified, 0, options), render_profile(verified, 1, options)

    columns = ("arrays", "corruptions", "named", "unnamed", "unchanged", "slipped")
    print(f"{'schedule':<18} " + " ".join(f"{c:>11}" for c in columns))
    total_bad = 0
    for scenario, path in SCENARIOS.items():
        loaded = load_scenario(path)
        for name, method in methods.items():
            schedule = method.schedule(loaded.route(), loaded.limits)
            if schedule.fallback_reason is not None:
                raise SystemExit(f"{scenario} {name}: fell back to exact ({schedule.fallback_reason.value})")
            original = exported(schedule)
            arrays = list(float_arrays(schedule))
            counts = dict.fromkeys(("named", "unnamed", "unchanged", "slipped"), 0)
            examples = []
            jobs = [(p, kind, bad) for p, array in arrays for kind, bad in every_corruption(array)]
            for array_path, kind, bad in progress(jobs, description=f"{scenario} {name}"):
                mutant = corrupted(schedule, array_path, bad)
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", RuntimeWarning)
                        files = exported(mutant)
                except VerificationError as error:
                    key = "named" if names("; ".join(error.details), array_path) else "unnamed"
                    counts[key] += 1
                    if key == "unnamed":
                        examples.append(f"unnamed: {array_path} ({kind}): {str(error)[:200]}")
                    continue
                if files == original:
                    counts["unchanged"] += 1
                else:
                    counts["slipped"] += 1
                    examples.append(f"slipped: {array_path} ({kind})")
            total_bad += counts["unnamed"] + counts["slipped"]
            figures = (len(arrays), len(jobs), *counts.values())
            print(f"{scenario + ' ' + name:<18} " + " ".join(f"{f:>11}" for f in figures))
            for line in examples[:10]:
                print("   ", line)
    if total_bad:
        raise SystemExit(f"{total_bad} corruptions were let through or refused without naming their array")


if __name__ == "__main__":
    main()
