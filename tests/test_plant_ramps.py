"""The simulated plant moves as a drive can: its speed never steps beyond its acceleration limit.

Issue 38, item 2: the speed went 0 -> 0.15 m/s in one cycle when a stop ended and 0.8 -> 0.4 m/s
when a slowdown started. Now only the brake of a stop (or of the executor's emergency stop) acts
at the emergency deceleration; every other change of speed ramps at most at ``max_acceleration``.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import REPO
from trajgen import load_scenario
from trajgen.execution.faults import FaultKind
from trajgen.execution.goals import schedule_for_execution
from trajgen.execution.simulation import parse_faults, simulate

PERIOD = 0.01

# several fault mixes on a junction and on a track graph: stops ending at speed, slowdowns starting at
# speed, position jumps, and all of them together. ``{1}`` and ``{2}`` stand for a time at which agv1
# or agv2 drives at its top speed in the plan (an exact plan moves one vehicle at a time).
CASES = [
    ("swap", ("stop:agv1@{1}+3",)),
    ("swap", ("stop:agv2@{2}+3", "slow:agv1@{1}+6=0.3")),
    ("swap", ("slow:agv2@{2}+8=0.4",)),
    ("swap", ("jump:agv1@{1}=0.04", "stop:agv1@{1}+2")),
    ("crossing", ("slow:agv1@{1}+5=0.2", "stop:agv2@{2}+4")),
    ("h", ("stop:agv1@{1}+4", "slow:agv2@{2}+10=0.25")),
    ("h", ("jump:agv2@{2}=-0.04", "stop:agv2@{2}+2")),
]


def _plan(name: str):
    folder = REPO / "examples" / ("graphs" if name == "h" else "")
    scenario = load_scenario(folder / f"{name}.toml")
    return scenario, schedule_for_execution(scenario, method="exact")


def _at_speed(schedule) -> tuple[str, str]:
    """For each vehicle, the first time it drives at 90 % of its top speed in ``schedule``, s."""
    t = np.linspace(0.0, schedule.duration, 2001)
    speed = np.abs(schedule.state(t).velocity)
    return tuple(f"{t[np.argmax(speed[v] >= 0.9 * speed[v].max())]:.2f}" for v in (0, 1))


@pytest.mark.parametrize(("name", "specs"), CASES, ids=[f"{n}-{'+'.join(s)}" for n, s in CASES])
def test_the_plant_changes_speed_at_most_at_its_limit_and_brakes_only_in_a_stop(name, specs):
    scenario, verified = _plan(name)
    faults = parse_faults(scenario, [spec.format(None, *_at_speed(verified.schedule)) for spec in specs])
    speeds: list[tuple[float, float]] = []
    braking: list[tuple[bool, bool]] = []

    def observe(executor, measured, command):
        t = len(speeds) * PERIOD  # when this measurement was taken, and the plant acts on the command
        speeds.append((measured[0].velocity, measured[1].velocity))
        stopped = [
            any(f.kind is FaultKind.STOP and f.vehicle == v and f.time <= t < f.end for f in faults)
            for v in (0, 1)
        ]
        braking.append((stopped[0] or command.emergency, stopped[1] or command.emergency))

    result, _ = simulate(scenario, faults, verified=verified, observer=observe)
    assert result.reached_goal
    assert result.violations == 0
    moved_at_speed = False
    for v, vehicle in enumerate(scenario.limits.vehicles):
        for k in range(len(speeds) - 1):
            change = abs(speeds[k + 1][v] - speeds[k][v]) / PERIOD
            # the brake acts within one cycle; everything else is the drive, within its acceleration
            limit = vehicle.emergency_braking if braking[k][v] else vehicle.max_acceleration
            assert change <= limit * (1 + 1e-6) + 1e-9, (v, k * PERIOD, change, limit)
            assert abs(speeds[k + 1][v]) <= vehicle.max_velocity * (1 + 1e-6), (v, k * PERIOD)
            moved_at_speed |= braking[k][v] and abs(speeds[k][v]) > 0.5 * vehicle.max_velocity
    assert moved_at_speed or not any(f.kind is FaultKind.STOP for f in faults)  # a stop came at speed


@pytest.mark.parametrize(
    ("specs", "window"),
    [
        (("lag:agv1@0.5=100", "stop:agv1@{1}+2"), (2.0, 4.0)),  # from its release on
        (("lag:agv1@0.5=180", "stop:agv1@{1}+1"), (1.0, 3.0)),
    ],
    ids=["lag-100-ms", "lag-180-ms"],
)
def test_a_lagging_drive_released_from_a_stop_ramps_too(specs, window):
    """A lag replays late setpoints as they come (a delay line); released from a brake it still ramps."""
    scenario, verified = _plan("swap")
    at_speed = _at_speed(verified.schedule)
    faults = parse_faults(scenario, [spec.format(None, *at_speed) for spec in specs])
    speeds: list[float] = []
    result, _ = simulate(
        scenario,
        faults,
        verified=verified,
        observer=lambda e, measured, c: speeds.append(measured[0].velocity),
    )
    assert result.reached_goal
    assert result.violations == 0
    start = round((float(at_speed[0]) + window[0]) / PERIOD)
    changes = np.abs(np.diff(speeds[start : round((float(at_speed[0]) + window[1]) / PERIOD)])) / PERIOD
    assert changes.max() <= scenario.limits.vehicles[0].max_acceleration * (1 + 1e-6)
    assert np.ptp(speeds[start : start + round(1.0 / PERIOD)]) > 0.1  # it did change speed there


def test_a_throttled_lagging_drive_is_a_delay_line_and_reaches_its_goal():
    """Campaign seed 11, scenario 40: a lag of 165 ms and a cap.

    Held to the ramp while throttled, the lagging drive ran 0.09 m off its path at a reversal and
    the executor braked for good (43,364 cycles; the default method falls back to exact there).
    """
    from trajgen.execution.goals import execution_margin
    from trajgen.scenario.sampling import campaign_faults, online_campaign

    scenario = online_campaign(41, seed=11)[40]
    verified = schedule_for_execution(scenario, method="exact")
    specs = campaign_faults(
        scenario, verified.schedule.duration, seed=1040, margin=execution_margin(scenario, 0.05)
    )
    assert any(spec.startswith("lag:") for spec in specs)
    assert any(spec.startswith("slow:") for spec in specs)
    result, _ = simulate(scenario, parse_faults(scenario, specs), verified=verified)
    assert result.reached_goal
    assert result.emergency_brakes == 0
    assert result.violations == 0
