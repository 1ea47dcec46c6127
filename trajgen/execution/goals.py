"""Plans meant for execution, and the one thing that re-plans: a new goal.

A plan for the executor keeps twice its position margin on top of the
separation (:func:`schedule_for_execution`): the executor's conflicts keep one
margin (room for a position correction), the other is clearance between
them, so no frontier stops a vehicle short of a reversal. Only a goal change
re-plans: both vehicles brake to rest, the topological planner plans from
where they stand, the timing method times it, the verifier certifies it
(:func:`schedule_from_rest`).
"""

from __future__ import annotations

import itertools

from limits import Limits
from topology import Configuration, EdgePoint, InfeasibleError, StarGraph, TrackGraph, plan, plan_graph
from trajgen.methods import make_schedule, method_for
from trajgen.model.schedule import TimingMethod
from trajgen.scenario import GraphScenario
from trajgen.verification import VerifiedSchedule, certify

__all__ = [
    "execution_margin",
    "goal_refusal",
    "graph_schedule_from_rest",
    "schedule_for_execution",
    "schedule_from_rest",
]


#: Metres a plan's closest approach may fall short of the separation plus twice the margin it was
#: planned for (the solver's and the verifier's round-off).
_CLEARANCE_ROUND_OFF = 1e-9


def execution_margin(scenario, position_margin: float, *, verified: VerifiedSchedule | None = None) -> float:
    """The position margin an executor can keep for ``scenario``, metres: at most ``position_margin``.

    The plan needs twice the margin on top of the separation (:func:`schedule_for_execution`), which must
    fit the shortest leg and the start and goal; where it does not, the margin shrinks (to 0 when the
    separation is the shortest leg). On a track graph: the start and goal, and the margin is 0 where
    the planner finds no route for the wider separation. With the plan at hand (``verified``), its
    closest approach is the room instead: nothing is planned, and a plan of any number of vehicles is
    taken.
    """
    track = scenario.track
    separation = scenario.limits.min_separation
    on_graph = isinstance(scenario, GraphScenario)
    if on_graph:
        room = min(
            track.distance(a, b)
            for points in (scenario.start, scenario.goal)
            for a, b in itertools.combinations(points, 2)
        )
    else:
        room = min(track.shortest_leg, track.separation(scenario.start), track.separation(scenario.goal))
    margin = max(0.0, min(position_margin, 0.5 * (room - separation)))
    if verified is not None:
        clearance = verified.report.min_separation - separation
        # the plan made for this margin keeps 2 margins to round-off; one made otherwise bounds it
        return margin if clearance >= 2.0 * margin - _CLEARANCE_ROUND_OFF else max(0.0, 0.5 * clearance)
    if on_graph:
        scenario.check_planned()
        if margin > 0.0:  # on a graph the wider separation may close a siding or a loop
            try:
                plan_graph(track, scenario.start, scenario.goal, min_separation=separation + 2.0 * margin)
            except InfeasibleError:
                return 0.0
    return margin


def schedule_from_rest(
    graph: StarGraph,
    limits: Limits,
    start: Configuration,
    goal: Configuration,
    *,
    method: TimingMethod | str | None,
    margin: float,
) -> VerifiedSchedule:
    """The verified plan from ``start`` to ``goal`` for the separation ``limits.min_separation + 2 margin``.

    Raises
    ------
    InputError
        The planner cannot keep that separation between ``start`` and ``goal``.
    VerificationError
        The timed plan fails the verifier (it is never executed).
    """
    separation = limits.min_separation + 2.0 * margin
    planned = Limits(limits.vehicles, separation)
    route = plan(graph, start, goal, min_separation=separation)
    return certify(make_schedule(route, planned, method=for_execution(method, graph)))


def graph_schedule_from_rest(
    track: TrackGraph,
    limits: Limits,
    start: tuple[EdgePoint, EdgePoint],
    goal: tuple[EdgePoint, EdgePoint],
    *,
    method: TimingMethod | str | None,
    margin: float,
    names: tuple[str, str] = ("vehicle 1", "vehicle 2"),
) -> VerifiedSchedule:
    """:func:`schedule_from_rest` on a track graph: the exact planner's route, timed, verified.

    Raises
    ------
    InfeasibleError
        No collision-free route keeps the separation ``limits.min_separation + 2 margin``.
    VerificationError
        The timed plan fails the verifier (it is never executed).
    """
    separation = limits.min_separation + 2.0 * margin
    route = plan_graph(track, start, goal, min_separation=separation, names=names)
    planned = Limits(limits.vehicles, separation)
    return certify(make_schedule(route, planned, method=for_execution(method, track)))


def for_execution(method: TimingMethod | str | None, track) -> TimingMethod:
    """``method`` as it plans for execution: ``optimal`` with the braking rule in its problem.

    ``None``: the default for ``track`` (:func:`~trajgen.methods.method_for`).
    """
    return method_for(method, track).for_execution()


def schedule_for_execution(
    scenario, *, method: TimingMethod | str | None = None, position_margin: float = 0.05
) -> VerifiedSchedule:
    """The verified schedule an :class:`~trajgen.execution.Executor` plays for ``scenario``.

    Planned for the separation ``min_separation + 2 * margin``, with the margin of
    :func:`execution_margin`: the executor's conflicts keep ``min_separation + margin``, and the
    second margin is the plan's clearance between them.
    """
    margin = execution_margin(scenario, position_margin)
    if isinstance(scenario, GraphScenario):
        return graph_schedule_from_rest(
            scenario.track,
            scenario.limits,
            scenario.start,
            scenario.goal,
            method=method,
            margin=margin,
            names=scenario.names,
        )
    return schedule_from_rest(
        scenario.track, scenario.limits, scenario.start, scenario.goal, method=method, margin=margin
    )


def goal_refusal(graph: StarGraph, goal: Configuration, required: float) -> str | None:
    """Why ``goal`` cannot be taken (the vehicles would end closer than ``required`` metres), or ``None``."""
    apart = graph.separation(goal)
    if apart < required:
        return f"goal {goal} leaves the vehicles {apart:.3f} m apart: expected at least {required:.3f} m"
    return None
