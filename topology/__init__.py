"""Exact collision-free motion planners for two vehicles on track graphs: junctions, sidings, loops.

Any track is a :class:`TrackGraph` (named nodes, edges with lengths; a point :class:`EdgePoint`):
:func:`plan_graph` gives the ℓ1-shortest one-at-a-time route on the roadmap of critical points
(docs/graphs.md). A single junction of 3 to 8 legs (:class:`StarGraph`, :class:`YGraph`) has the exact
algorithm of Baldi, *Collision-Free Motion Planning Algorithm in a Y-Graph* (:func:`plan`), with
the conventions of docs/planner.md: on a Y the configuration space deforms onto a circle, so two
continuous instructions suffice (topological complexity 2); with four to eight legs it deforms onto
the graph ``G_k`` and the planner takes one of three instructions (docs/star.md).

Examples
--------
>>> from topology import YGraph, Position, Configuration, plan
>>> track = YGraph({"A": 1.0, "B": 1.0, "C": 1.0})
>>> start = Configuration(Position("A", 1.0), Position("B", 1.0))
>>> route = plan(track, start, start.swapped())
>>> route.instruction
<Instruction.COUNTERCLOCKWISE: 'counterclockwise'>
>>> [str(w) for w in route.waypoints]
['(A:1, B:1)', '(A:1, O)', '(A:1, C:1)', '(O, C:1)', '(B:1, C:1)', '(B:1, O)', '(B:1, A:1)']
"""

from topology.boundary import BoundaryCycle
from topology.cycle import (
    ANTIPODAL_TOLERANCE,
    Cell,
    as_indexed,
    boundary_angle,
    classify,
    is_antipodal,
    retract,
)
from topology.errors import (
    InfeasibleError,
    InputError,
    OptionError,
    PositionError,
    SeparationError,
    TrackError,
    TrajgenError,
    VehicleCountError,
)
from topology.graph import MAX_LEGS, MIN_LEGS, StarGraph, YGraph
from topology.graph_planner import plan_graph, plan_graph_classes
from topology.graph_route import GraphMove, GraphRoute, class_signature
from topology.indexed import JUNCTION_INDEX, RegionKey, reduce_regions
from topology.options import Option
from topology.positions import JUNCTION, JUNCTION_NAME, Configuration, Position
from topology.retract_graph import Geodesic, GraphPoint, RetractGraph
from topology.route import Homotopy, Instruction, Region, Route, WayRound, plan, region_sequence
from topology.track_graph import EdgePoint, TrackEdge, TrackGraph
from topology.validation import PLANNED_VEHICLES, check_vehicle_count

__all__ = [
    "ANTIPODAL_TOLERANCE",
    "JUNCTION",
    "JUNCTION_INDEX",
    "JUNCTION_NAME",
    "MAX_LEGS",
    "MIN_LEGS",
    "PLANNED_VEHICLES",
    "BoundaryCycle",
    "Cell",
    "Configuration",
    "EdgePoint",
    "Geodesic",
    "GraphMove",
    "GraphPoint",
    "GraphRoute",
    "Homotopy",
    "InfeasibleError",
    "InputError",
    "Instruction",
    "Option",
    "OptionError",
    "Position",
    "PositionError",
    "Region",
    "RegionKey",
    "RetractGraph",
    "Route",
    "SeparationError",
    "StarGraph",
    "TrackEdge",
    "TrackError",
    "TrackGraph",
    "TrajgenError",
    "VehicleCountError",
    "WayRound",
    "YGraph",
    "as_indexed",
    "boundary_angle",
    "check_vehicle_count",
    "class_signature",
    "classify",
    "is_antipodal",
    "plan",
    "plan_graph",
    "plan_graph_classes",
    "reduce_regions",
    "region_sequence",
    "retract",
]
