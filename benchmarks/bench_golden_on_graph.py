"""Which golden files of the junction examples stay byte-identical when `exact` times them on the track graph.

Run: ``python benchmarks/bench_golden_on_graph.py`` (a few seconds).

The question before a junction's schedule becomes the one schedule model (issue 49, item 3): this
times every junction route of the golden suite (``tests/test_golden.py``) with ``exact`` on the
junction's track graph (:func:`~trajgen.model.junction_route.junction_graph_route`, then
``Exact.schedule_graph``) instead of the junction's own ``Exact.schedule``, renders every golden
file as the suite does, and prints for each case whether its bytes are the stored ones, and the
first difference where not. Cases timed by ``toppra`` are rendered as they are (unchanged) and
listed apart. The VDA 5050 runs are the order files of the schedule (the command's pipeline
around it is not one model yet).
"""

from __future__ import annotations

import sys
from datetime import UTC, datetime
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from tests.support.golden_profiles import CASES, GOLDEN, LONG_DIGESTS, first_difference  # noqa: E402
from trajgen.methods.exact import Exact  # noqa: E402
from trajgen.model.junction_route import junction_graph_route  # noqa: E402

VDA5050_CASES = ("swap-exact", "crossing-toppra")


def _on_the_track_graph(self, route, limits):
    """``Exact.schedule`` of a junction's route, as its track graph's route."""
    return self.schedule_graph(junction_graph_route(route), limits)


def _vda5050(case: str) -> str | None:
    """The first difference of a VDA 5050 golden run's files (the order files of its schedule), or None.

    Made from the schedule (:func:`~trajgen.export.vda5050.files.order_files`), not through the
    command: the pipeline around the schedule is not one model yet.
    """
    from trajgen import certify, load_scenario
    from trajgen.export.vda5050.files import order_files
    from trajgen.export.vda5050.options import Vda5050Options
    from trajgen.methods import make_schedule

    name, method = case.split("-")
    scenario = load_scenario(REPO / "examples" / f"{name}.toml")
    verified = certify(make_schedule(scenario.route(), scenario.limits, method=method))
    options = Vda5050Options(start_time=datetime(2026, 5, 1, 8, 0, tzinfo=UTC))
    made = order_files(verified, scenario.names, Path("out"), options=options)
    stored = GOLDEN.parent / "golden-vda5050" / case
    names = sorted(path.relative_to(stored) for path in stored.rglob("*.json"))
    if names != sorted(path.relative_to("out") for path in made):
        return "other files"
    for name in names:
        problem = first_difference((stored / name).read_bytes(), made[Path("out") / name])
        if problem is not None:
            return f"{name}: {problem}"
    return None


def main() -> None:
    from tests.support.golden_profiles import long_swap, profile_digests
    from trajgen.export.csv import CsvOptions

    Exact.schedule = _on_the_track_graph  # every exact schedule of the suite, on the track graph
    same = 0
    rows = []
    for case in CASES:
        rendered = case.render()
        folder = GOLDEN / case.name
        problems = [
            f"{name}: {problem}"
            for name, data in sorted(rendered.items())
            if (problem := first_difference((folder / name).read_bytes(), data)) is not None
        ]
        timed_by = "toppra" if "toppra" in case.name else "exact"
        rows.append((case.name, timed_by, problems[0] if problems else None))
        same += not problems
    for length, (duration, digests) in sorted(LONG_DIGESTS.items()):
        verified = long_swap(length)
        ok = verified.schedule.duration == duration and profile_digests(verified, CsvOptions()) == digests
        rows.append((f"long swap, {length:g} m legs (digests)", "exact", None if ok else "digests differ"))
        same += ok
    for case in VDA5050_CASES:
        problem = _vda5050(case)
        rows.append((f"vda5050 {case}", case.split("-")[1], problem))
        same += problem is None
    for name, timed_by, problem in rows:
        print(f"{name:>45}  {timed_by:>6}  {'identical' if problem is None else 'DIFFERS: ' + problem}")
    print(f"{same} of {len(rows)} identical")


if __name__ == "__main__":
    main()
