"""Where a simulated vehicle last said it stood, kept on disk for a restart (``--start last``).

A ``trajgen vehicle`` process writes the place of every state it publishes to a small file of its
own (:class:`VehicleMemory`: written over in place, padded, so a process killed with SIGKILL leaves
the last complete one).
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

__all__ = ["STATE_DIR_VARIABLE", "VehicleMemory", "memory_path", "remember", "remembered_place"]

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


#: The size the memory file is padded to, bytes (longer records grow it): every write covers the last.
_RECORD_BYTES = 512


class VehicleMemory:
    """A vehicle's memory file, open for its life: each state's place written over the last in place.

    One ``pwrite`` per state at offset 0, the record padded with spaces to the file's size, so the file
    is never half old and half new: a process killed at any moment (SIGKILL cannot split one write of a
    regular file) leaves the last complete place. A new file and a rename per state cost about a
    millisecond each here, which slowed a vehicle sending a hundred states a second.

    Parameters
    ----------
    path : Path

    Raises
    ------
    OSError
        The file cannot be made.
    """

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        self._size = _RECORD_BYTES

    @classmethod
    def opened(cls, path: Path, *, who: str) -> VehicleMemory | None:
        """The memory of vehicle ``who`` in ``path``; ``None``, said once, where it cannot be made."""
        try:
            return cls(path)
        except OSError as error:  # the vehicle drives on without its memory
            logger.warning("vehicle %s: cannot keep its place in %s: %s", who, path, error)
            return None

    def keep(self, state) -> bool:
        """Write where ``state`` (a vda5050 State) says the vehicle stands over what was there.

        Whether it could: a write that fails is said once, and the caller keeps no memory after it.
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
        data = json.dumps(record).encode()
        self._size = max(self._size, len(data) + 1)
        try:
            os.pwrite(self._fd, data.ljust(self._size, b" "), 0)
        except OSError as error:
            logger.warning(
                "vehicle %s: cannot keep its place in %s: %s", state.serial_number, self.path, error
            )
            return False
        return True

    def close(self) -> None:
        """Close the file (it stays, holding the last place)."""
        os.close(self._fd)

    def __enter__(self) -> VehicleMemory:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def remember(path: Path, state) -> bool:
    """Keep where a vehicle's VDA 5050 ``state`` says it stands in ``path`` (once); whether it could."""
    memory = VehicleMemory.opened(path, who=state.serial_number)
    if memory is None:
        return False
    with memory:
        return memory.keep(state)


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
