"""VDA 5050 2.1.0 orders of both vehicles, as files of a run or as messages for a live master.

The work is split by job; every public name of these modules is available from here:

- :mod:`~trajgen.export.vda5050.options`: the options of the messages and their checks
  (:class:`Vda5050Options`);
- :mod:`~trajgen.export.vda5050.path`: the nodes and edges of each vehicle's path, from its
  verified schedule;
- :mod:`~trajgen.export.vda5050.release`: which base each order and order update releases,
  and when (:func:`order_releases`);
- :mod:`~trajgen.export.vda5050.messages`: the one builder of the messages (vda5050-sdk models)
  and their bytes (:func:`render_orders`, :func:`render_manifest`);
- :mod:`~trajgen.export.vda5050.files`: the files of a run (:func:`write_orders`).
"""

from typing import TYPE_CHECKING

from trajgen.lazy import lazy_attributes

if TYPE_CHECKING:
    from trajgen.export.vda5050.files import order_files, order_paths, write_orders
    from trajgen.export.vda5050.messages import (
        VDA5050_VERSION,
        OrderMessage,
        edge_id,
        node_id,
        render_manifest,
        render_orders,
    )
    from trajgen.export.vda5050.options import MANIFEST_NAME, MAX_FIRST_HEADER_ID, Vda5050Options
    from trajgen.export.vda5050.path import (
        HOLD_MARGIN,
        NODE_TOLERANCE,
        NodeKind,
        OrderPath,
        PathEdge,
        PathNode,
    )
    from trajgen.export.vda5050.release import OrderReleases, Release, order_releases

_MODULES = {
    "files": ("order_files", "order_paths", "write_orders"),
    "messages": ("VDA5050_VERSION", "OrderMessage", "edge_id", "node_id", "render_manifest", "render_orders"),
    "options": ("MANIFEST_NAME", "MAX_FIRST_HEADER_ID", "Vda5050Options"),
    "path": ("HOLD_MARGIN", "NODE_TOLERANCE", "NodeKind", "OrderPath", "PathEdge", "PathNode"),
    "release": ("OrderReleases", "Release", "order_releases"),
}
#: Where each name lives: importing the face imports none of them.
_SOURCES = {name: f"{__name__}.{module}" for module, names in _MODULES.items() for name in names}

__all__ = [
    "HOLD_MARGIN",
    "MANIFEST_NAME",
    "MAX_FIRST_HEADER_ID",
    "NODE_TOLERANCE",
    "VDA5050_VERSION",
    "NodeKind",
    "OrderMessage",
    "OrderPath",
    "OrderReleases",
    "PathEdge",
    "PathNode",
    "Release",
    "Vda5050Options",
    "edge_id",
    "node_id",
    "order_files",
    "order_paths",
    "order_releases",
    "render_manifest",
    "render_orders",
    "write_orders",
]

__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
