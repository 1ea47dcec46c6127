"""The ``optimal`` method's classes on a track graph: each solved, the fastest verified one kept.

With ``homotopy="fastest"`` the route's class and up to two others (:func:`topology.plan_graph_classes`:
where the other vehicle yields) are solved by :func:`~trajgen.methods.graph_optimal.optimal_graph_schedule`,
each verified; the fastest is returned with every class's makespan in its
:class:`GraphOptimalInfo`. If none verifies, the ``exact`` schedule is returned, flagged.
"""

from __future__ import annotations

import dataclasses
import logging

from limits import Limits
from topology import GraphRoute, class_signature, plan_graph_classes
from trajgen.errors import InputError
from trajgen.methods.exact import Exact
from trajgen.methods.graph_optimal import optimal_graph_schedule
from trajgen.methods.graph_timing import check_graph_request
from trajgen.model.analysis import lower_bound
from trajgen.model.graph_schedule import GraphSchedule
from trajgen.model.schedule import FallbackReason, MethodInfo
from trajgen.model.summary import graph_class_label
from trajgen.verification import verify

__all__ = ["GraphClassResult", "GraphOptimalInfo", "graph_fallback", "solve_graph"]

logger = logging.getLogger(__name__)


def graph_fallback(route: GraphRoute, limits: Limits, reason: FallbackReason, detail: str) -> GraphSchedule:
    """The exact schedule of ``route`` in place of the optimal one, flagged with ``reason``."""
    logger.warning("optimal schedule of a graph fell back to exact (%s): %s", reason.value, detail)
    exact = Exact().schedule_graph(route, limits)
    return dataclasses.replace(
        exact, notes=(f"fallback to exact ({reason.value}): {detail}",), fallback_reason=reason
    )


@dataclasses.dataclass(frozen=True, slots=True)
class GraphClassResult:
    """One class of a track graph's route the optimal method solved.

    Attributes
    ----------
    label : str
        The class's moves, ``agv1 A -> c:1.5; agv2 D -> A; ...``.
    planned : bool
        Whether it is the planner's (shortest) route's class.
    lower_bound : float
        The lone-vehicle S-curve bound of the route, seconds (no schedule of any class is faster).
    makespan : float or None
        The verified optimal makespan, seconds (``None``: failed).
    chosen : bool
    failure : str or None
        Why it has no schedule.
    """

    label: str
    planned: bool
    lower_bound: float
    makespan: float | None
    chosen: bool
    failure: str | None

    def summary(self) -> dict:
        """JSON-ready fields, as a junction's classes."""
        return {
            "class": self.label,
            "homotopy": "planned" if self.planned else "other",
            "way_round": "not-applicable",
            "lower_bound_s": self.lower_bound,
            "makespan_s": self.makespan,
            "chosen": self.chosen,
            "failure": self.failure,
        }


@dataclasses.dataclass(frozen=True, slots=True)
class GraphOptimalInfo(MethodInfo):
    """Diagnostics of an optimal schedule on a track graph: the classes solved and how.

    Attributes
    ----------
    classes : tuple of GraphClassResult
    solver : str
        ``"ipopt"``.
    """

    classes: tuple[GraphClassResult, ...]
    solver: str = "ipopt"

    def summary(self) -> dict:
        """JSON-ready diagnostics."""
        return {
            "solver": self.solver,
            "time_limit_reached": any(c.failure == FallbackReason.TIME_LIMIT.value for c in self.classes),
            "classes": [c.summary() for c in self.classes],
        }


def _one_class(method, route: GraphRoute, limits: Limits) -> tuple[GraphSchedule | None, str | None]:
    """The verified optimal schedule of one class, or ``None`` and why not."""
    try:
        schedule = optimal_graph_schedule(route, limits, method)
    except InputError:
        raise
    except Exception as error:  # the solver's failures must not leave the library as a crash
        if "Maximum_WallTime" in str(error):
            return None, FallbackReason.TIME_LIMIT.value
        return None, f"{FallbackReason.SOLVER_FAILED.value}: {type(error).__name__}: {str(error)[:160]}"
    report = verify(schedule)
    if not report.passed:
        return None, f"{FallbackReason.VERIFICATION_FAILED.value}: {'; '.join(report.failures)[:300]}"
    return schedule, None


def solve_graph(method, route: GraphRoute, limits: Limits) -> GraphSchedule:
    """``method``'s optimal schedule of a route on a track graph, verified, or the flagged exact one.

    With ``homotopy="fastest"`` the route's class and up to two others
    (:func:`topology.plan_graph_classes`: where the other vehicle yields) are solved and the fastest
    verified schedule is returned, its ``route`` its class's; ``"planned"`` solves the route's class.
    Where the ``exact`` schedule is as fast (the vehicles never wait for each other), it is returned,
    with a note.

    Raises
    ------
    InputError
        A bad route or limits.
    """
    check_graph_request(route, limits)
    if route.count != 2:
        # the cells of this formulation are rectangles in the plane of two travels
        detail = (
            f"the optimal formulation on a track graph times two vehicles at once, the route moves "
            f"{route.count}: expected exact or toppra for {route.count}"
        )
        return graph_fallback(route, limits, FallbackReason.SETUP_FAILED, detail)
    routes = [route]
    if method.homotopy.value == "fastest":
        others = plan_graph_classes(
            route.track, route.start, route.goal, min_separation=route.min_separation, names=route.names
        )
        routes += [r for r in others if class_signature(r) != class_signature(route)]
    bound = lower_bound(route, limits)
    solved = [_one_class(method, r, limits) for r in routes]
    made = [(k, schedule) for k, (schedule, _) in enumerate(solved) if schedule is not None]
    # a tie within a microsecond keeps the route's own class (the first)
    chosen = min(made, key=lambda item: (round(item[1].duration, 6), item[0]))[0] if made else 0
    classes = tuple(
        GraphClassResult(
            graph_class_label(r),
            k == 0,
            bound,
            None if schedule is None else schedule.duration,
            k == chosen,
            failure,
        )
        for k, (r, (schedule, failure)) in enumerate(zip(routes, solved, strict=True))
    )
    info = GraphOptimalInfo(classes)
    if not made:
        failure = solved[0][1] or "no class solved"
        reason = (
            FallbackReason.TIME_LIMIT
            if failure == FallbackReason.TIME_LIMIT.value
            else (
                FallbackReason.VERIFICATION_FAILED
                if failure.startswith("verification")
                else FallbackReason.SOLVER_FAILED
            )
        )
        return dataclasses.replace(graph_fallback(route, limits, reason, failure), info=info)
    best = solved[chosen][0]
    exact = Exact().schedule_graph(route, limits)
    if exact.duration <= best.duration:  # the vehicles never meet: each move's own S-curve is optimal
        note = f"the moves one at a time ({exact.duration:.3f} s) are as fast as any solved class"
        return dataclasses.replace(exact, method=method, notes=(note,), info=info)
    return dataclasses.replace(best, info=info)
