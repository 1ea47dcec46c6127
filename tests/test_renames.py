"""The names renamed in 0.7 (issue 36): the new names work, and each old one still does, with a warning.

Each old name is listed in CHANGELOG.md and docs/upgrading.md; these tests hold the shims for the
one release they are promised, and would catch one that stopped warning or stopped working.
"""

from __future__ import annotations

import dataclasses
import importlib
import sys
from datetime import UTC, datetime

import pytest

from tests.conftest import REPO
from tests.support.cases import case
from topology import Homotopy, WayRound, plan
from trajgen.export.plc.dialects import DIALECTS
from trajgen.export.vda5050 import Vda5050Options, order_releases, render_manifest, render_orders
from trajgen.methods import METHODS
from trajgen.methods.optimal.choice import HomotopyChoice

RENAMED = pytest.mark.filterwarnings("error::DeprecationWarning")


@pytest.fixture(scope="module")
def swap():
    return case("y").scenario(), case("y").verified("exact")


@RENAMED
def test_scenario_route_is_the_planners_route_and_plan_is_its_old_name(swap):
    scenario, _ = swap
    separation = scenario.limits.min_separation
    expected = plan(scenario.track, scenario.start, scenario.goal, min_separation=separation)
    assert scenario.route() == expected
    with pytest.warns(DeprecationWarning, match=r"Scenario\.plan\(\) is deprecated: use Scenario\.route\(\)"):
        assert scenario.plan() == expected


@RENAMED
@pytest.mark.parametrize("owner", [*METHODS, *DIALECTS], ids=lambda owner: str(owner.name))
def test_a_description_is_one_line_and_summary_is_its_old_name(owner):
    assert isinstance(owner.description, str)
    assert owner.description
    assert "\n" not in owner.description
    deprecated = r"\.summary is deprecated since trajgen 0\.7: use \.description"
    with pytest.warns(DeprecationWarning, match=deprecated):
        assert owner.summary == owner.description


@RENAMED
@pytest.mark.parametrize(("jerk_limited", "expected"), [(True, 2), (False, 1)])
def test_smoothness_is_one_number_and_continuity_its_old_keyword(swap, jerk_limited, expected):
    schedule = swap[1].schedule
    default = dataclasses.replace(schedule, jerk_limited=jerk_limited, smoothness=None)
    assert default.smoothness == expected
    assert dataclasses.replace(schedule, smoothness=0).smoothness == 0
    with pytest.warns(DeprecationWarning, match=r"Schedule\(continuity=\.\.\.\) is deprecated.*smoothness="):
        old = dataclasses.replace(schedule, continuity=0)
    assert old.smoothness == 0
    assert "continuity" not in {field.name for field in dataclasses.fields(schedule)}


@RENAMED
@pytest.mark.parametrize(
    ("option", "old", "new"),
    [
        (Homotopy, "paper", Homotopy.PLANNED),
        (HomotopyChoice, "paper", HomotopyChoice.PLANNED),
        (WayRound, "graph", WayRound.NOT_APPLICABLE),
    ],
)
def test_an_old_option_value_is_taken_with_a_warning_and_listed_nowhere(option, old, new):
    assert option.lookup(new.value) is new
    deprecated = rf"{old!r} is deprecated since trajgen 0\.7: use {new.value!r}"
    with pytest.warns(DeprecationWarning, match=deprecated):
        assert option.lookup(old) is new
    assert old not in [member.value for member in option]
    assert getattr(option, old.upper()) is new  # the old member name, an alias


@RENAMED
def test_the_route_of_four_legs_goes_round_nothing():
    from topology import Configuration, Position, StarGraph

    crossing = StarGraph({"N": 10.0, "W": 10.0, "S": 10.0, "E": 10.0})
    start = Configuration(Position("N", 10.0), Position("S", 10.0))
    route = plan(crossing, start, start.swapped())
    assert (route.homotopy, route.way_round) == (Homotopy.PLANNED, WayRound.NOT_APPLICABLE)


@RENAMED
def test_order_releases_is_the_keyword_and_plan_its_old_name(swap):
    scenario, verified = swap
    releases = order_releases(verified)
    options = Vda5050Options(start_time=datetime(2026, 1, 1, tzinfo=UTC))
    new = render_orders(verified, scenario.names, options=options, releases=releases)
    with pytest.warns(DeprecationWarning, match=r"render_orders\(plan=\.\.\.\) is deprecated"):
        old = render_orders(verified, scenario.names, options=options, plan=releases)
    assert [m.data for m in old] == [m.data for m in new]
    manifest = render_manifest(verified, scenario.names, new, options=options, releases=releases)
    with pytest.warns(DeprecationWarning, match=r"render_manifest\(plan=\.\.\.\) is deprecated"):
        assert render_manifest(verified, scenario.names, new, options=options, plan=releases) == manifest


@pytest.mark.parametrize(
    ("old", "new", "names"),
    [
        ("trajgen.online", "trajgen.execution", ("Executor", "schedule_for_execution", "BrakingCheck")),
        ("trajgen.closed_loop", "trajgen.simulation_pipeline", ("run_simulation", "SimulationRun")),
    ],
)
def test_a_renamed_package_imports_with_a_warning_and_gives_the_same_objects(old, new, names, monkeypatch):
    monkeypatch.delitem(sys.modules, old, raising=False)
    with pytest.warns(DeprecationWarning, match=rf"{old} is deprecated: import from {new}"):
        shim = importlib.import_module(old)
    current = importlib.import_module(new)
    for name in names:
        assert getattr(shim, name) is getattr(current, name)
    if old == "trajgen.online":
        assert shim.plan_for_execution is current.schedule_for_execution


def test_every_renamed_name_is_listed_for_upgraders():
    upgrading = (REPO / "docs" / "upgrading.md").read_text(encoding="utf-8")
    changelog = (REPO / "CHANGELOG.md").read_text(encoding="utf-8")
    for old, new in [
        ("Scenario.plan()", "Scenario.route()"),
        (".summary", ".description"),
        ("continuity=", "smoothness="),
        ("Homotopy.PAPER", "Homotopy.PLANNED"),
        ("HomotopyChoice.PAPER", "HomotopyChoice.PLANNED"),
        ("WayRound.GRAPH", "WayRound.NOT_APPLICABLE"),
        ("plan_for_execution", "schedule_for_execution"),
        ("trajgen.online", "trajgen.execution"),
        ("trajgen.closed_loop", "trajgen.simulation_pipeline"),
        ("plan=", "releases="),
        ("plan_orders", "order_releases"),
        ("paper_class", "planned_class"),
    ]:
        for text, where in ((upgrading, "docs/upgrading.md"), (changelog, "CHANGELOG.md")):
            assert old in text, f"{where} does not list {old} -> {new}"
            assert new in text, f"{where} does not list {old} -> {new}"
