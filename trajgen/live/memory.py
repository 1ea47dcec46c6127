"""Where a simulated vehicle last said it stood, kept on disk for a restart (``--start last``).

A ``trajgen vehicle`` process writes the place of every state it publishes to a small file of its
own (replaced whole each time, so a process killed with SIGKILL leaves the last complete one).
Started again with ``--start last`` it stands there: where it stood when it was killed, as the
master last heard it. The folder is ``$TRAJGEN_STATE_DIR`` if set, else the user state folder of
the platform (``~/.local/state/trajgen`` on Linux), subfolder ``vehicles``.
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path

from topology import EdgePoint, Position, StarGraph, TrackGraph
from trajgen.errors import InputError
from trajgen.live.geometry import track_position
from trajgen.live.mqtt import BrokerSettings, VehicleIdentity

__all__ = ["STATE_DIR_VARIABLE", "memory_path", "remember", "remembered_place"]

logger = logging.getLogger(__name__)

#: The environment variable naming the folder vehicles keep their places in.
STATE_DIR_VARIABLE = "TRAJGEN_STATE_DIR"


def memory_path(identity: VehicleIdentity, broker: BrokerSettings) -> Path:
    """The file where the vehicle of ``identity`` on ``broker`` keeps where it stands.

    One file per broker and identity: vehicles of the same serial number on two brokers (two plants,
    two test runs) keep their places apart.
    """
    configured = os.environ.get(STATE_DIR_VARIABLE)
    if configured:
        folder = Path(configured)
    else:
        import platformdirs

        folder = Path(platformdirs.user_state_dir("trajgen", appauthor=False))
    parts = (broker.host, str(broker.port), identity.interface, identity.version, identity.manufacturer)
    name = "-".join((*parts, identity.serial_number)).replace(os.sep, "_")
    return folder / "vehicles" / f"{name}.json"


def remember(path: Path, state) -> bool:
    """Keep where a vehicle's VDA 5050 ``state`` says it stands in ``path``; whether it could.

    The file is replaced whole (written beside it, then renamed): a process killed at any moment
    leaves the last complete place. A file that cannot be written is said once, by the caller's
    giving up on it.
    """
    position = state.agv_position
    record = {
        "serialNumber": state.serial_number,
        "lastNodeId": state.last_node_id,
        "nextNodeId": state.node_states[0].node_id if state.node_states else "",
        "distanceSinceLastNode": state.distance_since_last_node or 0.0,
        "x": None if position is None else position.x,
        "y": None if position is None else position.y,
    }
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary.write_text(json.dumps(record), encoding="utf-8")
        os.replace(temporary, path)
    except OSError as error:
        logger.warning("vehicle %s: cannot keep its place in %s: %s", state.serial_number, path, error)
        return False
    return True


def remembered_place(track: StarGraph | TrackGraph, path: Path) -> Position | EdgePoint:
    """The place a vehicle's memory file says it last stood at, on ``track``.

    Raises
    ------
    InputError
        No such file, a file that is not a vehicle's memory, or a place not on ``track``.
    """
    from trajgen.live.places import snapshot_point

    try:
        record = json.loads(Path(path).read_text(encoding="utf-8"))
        node, following = str(record["lastNodeId"]), str(record["nextNodeId"])
        along = float(record["distanceSinceLastNode"])
        x, y = record["x"], record["y"]
    except FileNotFoundError:
        raise InputError(
            f"--start last: no place is kept in {str(path)!r} (this vehicle never published a state here): "
            "expected --start EDGE:S, LEG:S or a node"
        ) from None
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise InputError(f"--start last: {str(path)!r} is not a vehicle's memory ({error})") from None
    if isinstance(track, TrackGraph):
        if not node:
            raise InputError(f"--start last: {str(path)!r} names no node: expected --start EDGE:S or a node")
        return snapshot_point(track, node, following, along)
    if x is None or y is None:
        raise InputError(f"--start last: {str(path)!r} has no x/y: expected --start LEG:S")
    return track_position(track, float(x), float(y))
