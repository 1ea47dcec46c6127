"""The live master's decisions without a broker: the start check, the streamed log, the timeline, places.

Issue 48: closed-form cases of :func:`~trajgen.live.start_check.start_decision` (wait, cancel, begin,
plan, refuse), the run log streamed to ``FILE.partial``, the lines ``serve`` prints, where a state
puts a vehicle, the vehicle's memory, and the one default method per track.
"""

from __future__ import annotations

import json
import types

import pytest

from tests.conftest import REPO
from topology import EdgePoint, Position
from trajgen.cli.timeline import Timeline, timeline_line
from trajgen.errors import InputError
from trajgen.execution.tracks import GraphTrack, JunctionTrack
from trajgen.live.memory import VehicleMemory, memory_path, remember, remembered_place
from trajgen.live.mqtt import BrokerSettings, VehicleIdentity
from trajgen.live.places import reported_place
from trajgen.live.runlog import RunLog
from trajgen.live.start_check import start_decision
from trajgen.live.view import VehicleView
from trajgen.methods import method_for
from trajgen.scenario import load_scenario

SWAP = load_scenario(REPO / "examples" / "swap.toml")
H = load_scenario(REPO / "examples" / "graphs" / "h.toml")


def _views(places, **fields) -> list[VehicleView]:
    views = []
    for k, place in enumerate(places):
        view = VehicleView(f"agv{k + 1}", VehicleIdentity("unspecified", f"agv{k + 1}"))
        view.place, view.heard = place, True
        for key, values in fields.items():
            setattr(view, key, values[k])
        views.append(view)
    return views


def _decide(scenario, places, *, planned_from=None, goal_pending=False, **fields):
    track = GraphTrack(scenario.track) if scenario is H else JunctionTrack(scenario.track)
    starts = list(scenario.start) if scenario is H else [scenario.start.first, scenario.start.second]
    return start_decision(
        scenario.track,
        track,
        _views(places, **fields),
        starts,
        separation=scenario.limits.min_separation,
        planned_from=planned_from,
        goal_pending=goal_pending,
    )


# -- the start check: closed-form cases ------------------------------------------------------------------


def test_every_vehicle_at_the_plans_start_begins():
    assert _decide(H, list(H.start)).action == "begin"
    assert _decide(SWAP, [SWAP.start.first, SWAP.start.second]).action == "begin"


def test_a_place_within_a_millimetre_of_the_start_is_the_start_and_two_are_not():
    a, d = H.start
    near = H.track.point(EdgePoint(a.edge, a.s - 0.0009)) if a.s > 0 else H.track.point("a:0.0009")
    assert _decide(H, [near, d]).action == "begin"
    assert _decide(H, [H.track.point("a:0.002"), d]).action == "plan"


@pytest.mark.parametrize(
    ("fields", "action"),
    [
        pytest.param({"place": [None, "D"]}, "wait", id="a-vehicle-said-no-place"),
        pytest.param({"driving": [True, False]}, "wait", id="a-vehicle-drives"),
        pytest.param({"foreign": ["old-agv1", None]}, "cancel", id="an-earlier-runs-order"),
    ],
)
def test_the_start_waits_or_cancels_before_it_compares(fields, action):
    places = [H.track.point(p) if isinstance(p, str) else p for p in fields.pop("place", list(H.start))]
    decision = _decide(H, places, **fields)
    assert decision.action == action
    if action == "cancel":
        assert decision.vehicles == (0,)
        assert decision.why == "it still holds order 'old-agv1' of an earlier run"


def test_a_vehicle_elsewhere_is_planned_from_where_the_vehicles_stand():
    places = [H.track.point("e:3"), H.start[1]]
    decision = _decide(H, places)
    assert (decision.action, decision.off, decision.places) == ("plan", (0,), tuple(places))


def test_vehicles_closer_than_the_separation_are_refused_naming_them_and_their_places():
    decision = _decide(H, [H.track.point("e:5.5"), H.start[1]])
    assert decision.action == "refuse"
    assert decision.off == (0,)
    assert decision.why == (
        "master: agv1 at e:5.5 and agv2 at D stand 1.000 m apart, closer than the separation 1.5 m: "
        "no plan starts there (move them apart and start again); no order was sent"
    )


def test_a_plan_made_from_these_places_that_still_does_not_start_there_is_refused_not_made_again():
    places = (H.track.point("e:3"), H.start[1])
    decision = _decide(H, list(places), planned_from=places)
    assert decision.action == "refuse"
    assert "does not start there" in decision.why


def test_a_goal_asked_before_the_first_orders_plans_from_where_they_stand():
    assert _decide(H, list(H.start), goal_pending=True).action == "plan"


# -- where a state puts a vehicle ------------------------------------------------------------------------


def _state(**fields):
    defaults = {"last_node_id": "", "node_states": [], "distance_since_last_node": 0.0, "agv_position": None}
    return types.SimpleNamespace(**{**defaults, **fields})


def test_a_state_places_its_vehicle_by_its_node_on_a_graph_and_by_x_y_on_a_junction():
    node = types.SimpleNamespace(node_id="e:4")
    assert H.track.distance(reported_place(H.track, _state(last_node_id="e:3")), H.track.point("e:3")) == 0.0
    half = reported_place(
        H.track, _state(last_node_id="e:3", node_states=[node], distance_since_last_node=0.5)
    )
    assert H.track.distance(half, H.track.point("e:3.5")) == pytest.approx(0.0, abs=1e-12)
    where = types.SimpleNamespace(x=0.0, y=7.0)
    assert reported_place(SWAP.track, _state(agv_position=where)) == Position("A", 7.0)
    assert reported_place(SWAP.track, _state(last_node_id="B:3")) == Position("B", 3.0)
    assert reported_place(H.track, _state()) is None


def test_a_state_naming_no_place_of_the_track_is_refused_naming_it():
    with pytest.raises(InputError, match=r"lastNodeId 'z:1' is not a place on the track: edge 'z' is not on"):
        reported_place(H.track, _state(last_node_id="z:1"))
    with pytest.raises(
        InputError, match=r"lastNodeId 'Q:1' is not a place on the junction: expected O or LEG:s"
    ):
        reported_place(SWAP.track, _state(last_node_id="Q:1"))


# -- the vehicle's memory (--start last) -------------------------------------------------------------------


def test_a_vehicle_remembers_where_it_stood_and_starts_there_again(tmp_path, monkeypatch):
    monkeypatch.setenv("TRAJGEN_STATE_DIR", str(tmp_path))
    identity = VehicleIdentity("unspecified", "agv1")
    path = memory_path(identity, BrokerSettings.from_url("mqtt://127.0.0.1:1883"))
    other = memory_path(identity, BrokerSettings.from_url("mqtt://127.0.0.1:1884"))
    assert path.parent == tmp_path / "vehicles"
    assert path != other  # one memory per broker: two test runs or plants keep theirs apart
    node = types.SimpleNamespace(node_id="e:4")
    state = _state(
        serial_number="agv1", last_node_id="e:3", node_states=[node], distance_since_last_node=0.25
    )
    assert remember(path, state)
    assert json.loads(path.read_text())["lastNodeId"] == "e:3"
    assert H.track.distance(remembered_place(H.track, path), H.track.point("e:3.25")) == pytest.approx(0.0)
    assert not list(path.parent.glob(".*tmp"))  # replaced whole: no temporary left


def test_the_memory_is_written_over_in_place_and_always_reads_back_whole(tmp_path):
    """One ``pwrite`` per state, padded: a shorter place over a longer one leaves no tail of it."""
    path = tmp_path / "agv1.json"
    long_node = types.SimpleNamespace(node_id="e:" + "3" * 300)  # longer than the padding: it grows
    places = [
        _state(
            serial_number="agv1", last_node_id="e:3.25", node_states=[long_node], distance_since_last_node=0.5
        ),
        _state(serial_number="agv1", last_node_id="D"),
    ]
    with VehicleMemory(path) as memory:
        for state in places:
            assert memory.keep(state)
            assert json.loads(path.read_text())["lastNodeId"] == state.last_node_id
    assert json.loads(path.read_text())["nextNodeId"] == ""  # nothing of the longer record survives
    assert H.track.distance(remembered_place(H.track, path), H.track.point("D")) == 0.0


@pytest.mark.parametrize(
    ("content", "match"),
    [
        pytest.param(None, r"--start last: no place is kept in .*: expected --start EDGE:S", id="missing"),
        pytest.param("not json", "is not a vehicle's memory", id="damaged"),
    ],
)
def test_a_memory_that_cannot_be_read_is_refused_naming_the_file(content, match, tmp_path):
    path = tmp_path / "agv1.json"
    if content is not None:
        path.write_text(content)
    with pytest.raises(InputError, match=match):
        remembered_place(H.track, path)


# -- the run log, streamed ---------------------------------------------------------------------------------


def test_the_run_log_is_on_disk_record_by_record_and_an_earlier_partial_log_is_kept(tmp_path):
    target = tmp_path / "run.jsonl"
    (tmp_path / "run.jsonl.partial").write_text('{"t": 0, "event": "end"}\n')  # a killed run's
    log = RunLog.streamed(target)
    try:
        log.write({"t": 0.0, "event": "planning", "what": "x", "method": "exact"})
        # without close or flush by the caller: a SIGKILL now leaves this on disk
        assert json.loads((tmp_path / "run.jsonl.partial").read_text())["event"] == "planning"
        assert (tmp_path / "run.jsonl.partial.1").read_text() == '{"t": 0, "event": "end"}\n'
        assert [r["event"] for r in log.records()] == ["planning"]
    finally:
        log.close()
    assert not (tmp_path / "run.jsonl.partial").exists()  # closed once committed
    assert (tmp_path / "run.jsonl.partial.1").exists()


def test_a_log_kept_after_a_failed_commit_stays(tmp_path):
    log = RunLog.streamed(tmp_path / "run.jsonl")
    log.write({"t": 0.0, "event": "end", "outcome": "timed-out", "makespan_s": 0.0})
    log.close(keep=True)
    assert (tmp_path / "run.jsonl.partial").exists()


def test_a_partial_log_that_cannot_be_made_is_an_output_error_naming_it(tmp_path):
    (tmp_path / "file").write_text("")
    with pytest.raises(InputError, match=r"cannot write the run log '.*run.jsonl.partial' as the run goes"):
        RunLog.streamed(tmp_path / "file" / "run.jsonl")


# -- the timeline -----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("record", "line"),
    [
        (
            {"event": "planning", "what": "the scenario's start", "method": "exact"},
            "planning the scenario's start (exact)",
        ),
        (
            {"event": "off-start", "vehicle": "agv1", "at": "e:3", "start": "A"},
            "agv1 stands at e:3, not at A where the plan starts it: no order is sent",
        ),
        (
            {
                "event": "order",
                "vehicle": "agv1",
                "resent": False,
                "first": 0,
                "frontier_m": 15.6,
                "update": 0,
            },
            "agv1: order, base to 15.60 m along its path",
        ),
        (
            {
                "event": "order",
                "vehicle": "agv1",
                "resent": False,
                "first": 3,
                "frontier_m": 16.0,
                "update": 1,
            },
            None,
        ),
        ({"event": "state", "vehicle": "agv1"}, None),
        (
            {"event": "stop", "reason": "SIGINT", "cancelled": ["agv1", "agv2"]},
            "stopped by SIGINT: nothing more released, cancelOrder to agv1, agv2",
        ),
    ],
)
def test_each_event_makes_its_line_and_updates_and_states_none(record, line):
    assert timeline_line({"t": 0.0, **record}) == line


def test_the_timeline_times_its_lines_from_when_it_was_made(capsys):
    clock = types.SimpleNamespace(values=iter([10.0, 12.5]), now=None)
    clock.now = lambda: next(clock.values)
    Timeline(clock)({"t": 0.0, "event": "end", "outcome": "goals-reached"})
    assert capsys.readouterr().out == "     2.50 s  end: goals-reached\n"


# -- one default method --------------------------------------------------------------------------------------


def test_one_default_method_per_track_for_every_command():
    assert method_for(None, H.track).name == "exact"
    assert method_for(None, SWAP.track).name == "optimal"
    assert method_for("toppra", H.track).name == "toppra"
