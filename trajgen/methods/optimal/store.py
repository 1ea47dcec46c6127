"""Compiled NLPs kept on disk across processes: built once per machine, loaded in a fraction of the time.

Building the NLP of one shape (transcription and CasADi's derivatives) takes about 0.36 s without
the braking rule and 1.6 s with it; loading it from this store (read, decompress, deserialize)
0.14 s and 0.7 s (medians on a 2-core machine). A :class:`NlpStore` keeps each shape's fatrop
solver (CasADi's own serialization, zlib compressed) with the bounds and equality flags of its
transcription, in one file per shape:

* the file name is a hash of everything the compiled function depends on: the shape, the solver
  options, this module's format version, the CasADi version and the machine; another CasADi
  gives other files, never a stale one;
* a file is written to a temporary name and renamed into place (atomic on one file system), so
  processes writing the same shape at once leave one whole file; a file that does not read back
  whole (a checksum over its payload) is deleted and the shape built again;
* the folder is kept under ``max_bytes``: the least recently used files are deleted first.

A solver loaded from the store computes bit for bit what the freshly built one computes (the
serialization stores the same expression graphs), so a schedule does not depend on whether its
NLP was built or loaded.

The folder is ``$TRAJGEN_CACHE_DIR`` if set (the empty string turns the store off), else the
user cache folder of the platform (``~/.cache/trajgen`` on Linux), subfolder ``nlp``.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import platform
import tempfile
import threading
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["CACHE_DIR_VARIABLE", "DEFAULT_MAX_BYTES", "NlpStore", "StoredNlp", "default_store"]

logger = logging.getLogger(__name__)

#: The environment variable naming the cache folder ("" turns the disk cache off).
CACHE_DIR_VARIABLE = "TRAJGEN_CACHE_DIR"
#: Default bound of the folder's size: about 30 shapes with the braking rule (8.5 MB each).
DEFAULT_MAX_BYTES = 256 * 1024 * 1024
#: Bumped whenever the transcription or the stored layout changes: old files are then not read.
FORMAT = 1
_MAGIC = b"trajgen-nlp\n"
#: zlib level: 1 compresses a braking-rule solver 64 -> 8.5 MB in 0.24 s, decompressed in 0.15 s.
_COMPRESSION = 1
_SUFFIX = ".nlp"


@dataclass(frozen=True, slots=True)
class StoredNlp:
    """What a store file holds for one shape.

    Attributes
    ----------
    solver : str
        The fatrop solver, CasADi-serialized.
    bounds : dict of str to ndarray
        ``lbx``, ``ubx``, ``lbg``, ``ubg`` of the transcription (SI units).
    equality : tuple of bool
        Which constraints are equalities.
    """

    solver: str
    bounds: dict
    equality: tuple[bool, ...]


def _casadi_version() -> str:
    import casadi

    return casadi.__version__


class NlpStore:
    """A folder of compiled NLPs, one file per shape and solver options (thread- and process-safe).

    Parameters
    ----------
    directory : str or Path
        Where the files are kept (created on first write).
    max_bytes : int, optional
        Most bytes the folder's files may take (default :data:`DEFAULT_MAX_BYTES`).
    """

    __slots__ = ("_lock", "_pending", "directory", "max_bytes")

    def __init__(self, directory: str | os.PathLike, *, max_bytes: int = DEFAULT_MAX_BYTES) -> None:
        if isinstance(max_bytes, bool) or not isinstance(max_bytes, int) or max_bytes < 1:
            raise ValueError(f"NLP store max_bytes must be an integer >= 1, got {max_bytes!r}")
        self.directory = Path(directory)
        self.max_bytes = max_bytes
        self._lock = threading.Lock()
        self._pending: list[threading.Thread] = []

    def __repr__(self) -> str:
        return f"NlpStore({str(self.directory)!r}, max_bytes={self.max_bytes})"

    def key(self, description: str) -> str:
        """The file name stem of the compiled NLP that ``description`` (shape and options) names."""
        text = f"{FORMAT}|{_casadi_version()}|{platform.machine()}|{description}"
        return hashlib.sha256(text.encode()).hexdigest()[:40]

    def path(self, description: str) -> Path:
        """The file of ``description``'s compiled NLP."""
        return self.directory / (self.key(description) + _SUFFIX)

    def load(self, description: str) -> StoredNlp | None:
        """The stored NLP of ``description``, or ``None`` (not stored, unreadable or damaged)."""
        path = self.path(description)
        try:
            data = path.read_bytes()
        except OSError:
            return None
        try:
            stored = _decode(data)
        except (ValueError, KeyError, zlib.error, UnicodeDecodeError) as error:
            logger.warning("optimal: the stored NLP %s is damaged (%s); it is built again", path.name, error)
            with contextlib.suppress(OSError):
                path.unlink()
            return None
        with contextlib.suppress(OSError):
            os.utime(path)  # most recently used: evicted last
        return stored

    def save(self, description: str, stored: StoredNlp) -> None:
        """Write ``stored`` for ``description`` (atomically), then keep the folder under ``max_bytes``."""
        data = _encode(stored)
        self.directory.mkdir(parents=True, exist_ok=True)
        target = self.path(description)
        handle, temporary = tempfile.mkstemp(dir=self.directory, prefix=".writing-", suffix=_SUFFIX)
        try:
            with os.fdopen(handle, "wb") as file:
                file.write(data)
            os.replace(temporary, target)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
            raise
        self._evict()

    def save_later(self, description: str, serialize, bounds: dict, equality: tuple[bool, ...]) -> None:
        """Serialize and save in a background thread (CasADi releases the GIL while it serializes).

        ``serialize`` returns the solver's serialization, or ``None`` to save nothing. A failure is
        logged, never raised: the store only saves time. :meth:`flush` waits for the writes still
        under way.
        """

        def write() -> None:
            try:
                solver = serialize()
                if solver is None:  # the NLP stayed busy (a solve that never returned): not kept
                    logger.debug("optimal: a compiled NLP was not kept: its solver stayed busy")
                    return
                self.save(description, StoredNlp(solver, bounds, equality))
            except Exception as error:  # a full disk or a read-only folder must not fail a schedule
                logger.warning("optimal: could not keep the compiled NLP in %s: %s", self.directory, error)

        thread = threading.Thread(target=write, name="trajgen-nlp-store")
        with self._lock:
            self._pending = [t for t in self._pending if t.is_alive()]
            self._pending.append(thread)
        thread.start()

    def flush(self, timeout: float | None = None) -> bool:
        """Wait for the background writes; returns whether all finished (within ``timeout`` seconds)."""
        with self._lock:
            pending = list(self._pending)
        for thread in pending:
            thread.join(timeout)
        return not any(thread.is_alive() for thread in pending)

    def files(self) -> list[Path]:
        """The stored NLP files, least recently used first."""
        try:
            entries = [(path.stat().st_mtime, path) for path in self.directory.glob("*" + _SUFFIX)]
        except OSError:
            return []
        return [path for _, path in sorted(entries)]

    def clear(self) -> None:
        """Delete every stored NLP."""
        for path in self.files():
            with contextlib.suppress(OSError):
                path.unlink()

    def _evict(self) -> None:
        files = [(path, _size(path)) for path in self.files()]
        total = sum(size for _, size in files)
        for path, size in files:
            if total <= self.max_bytes:
                break
            with contextlib.suppress(OSError):
                path.unlink()
                total -= size


def _size(path: Path) -> int:
    try:
        return path.stat().st_size
    except OSError:
        return 0


def _encode(stored: StoredNlp) -> bytes:
    arrays = {
        name: np.ascontiguousarray(stored.bounds[name], dtype="<f8") for name in ("lbx", "ubx", "lbg", "ubg")
    }
    payload = zlib.compress(stored.solver.encode("ascii"), _COMPRESSION)
    blobs = [arrays[name].tobytes() for name in ("lbx", "ubx", "lbg", "ubg")]
    equality = np.packbits(np.array(stored.equality, dtype=bool)).tobytes()
    body = b"".join([payload, *blobs, equality])
    header = {
        "solver": len(payload),
        "bounds": [len(blob) // 8 for blob in blobs],
        "equality": len(stored.equality),
        "sha256": hashlib.sha256(body).hexdigest(),
    }
    return _MAGIC + json.dumps(header).encode() + b"\n" + body


def _decode(data: bytes) -> StoredNlp:
    if not data.startswith(_MAGIC):
        raise ValueError("not a stored NLP")
    end = data.index(b"\n", len(_MAGIC))
    header = json.loads(data[len(_MAGIC) : end])
    body = data[end + 1 :]
    if hashlib.sha256(body).hexdigest() != header["sha256"]:
        raise ValueError("checksum mismatch")
    cursor = header["solver"]
    solver = zlib.decompress(body[:cursor]).decode("ascii")
    bounds = {}
    for name, count in zip(("lbx", "ubx", "lbg", "ubg"), header["bounds"], strict=True):
        bounds[name] = np.frombuffer(body[cursor : cursor + 8 * count], dtype="<f8").astype(float)
        cursor += 8 * count
    flags = np.unpackbits(np.frombuffer(body[cursor:], dtype=np.uint8))[: header["equality"]]
    if flags.size != header["equality"]:
        raise ValueError("truncated equality flags")
    return StoredNlp(solver, bounds, tuple(bool(flag) for flag in flags))


def default_store() -> NlpStore | None:
    """The store in ``$TRAJGEN_CACHE_DIR`` or the user cache folder; ``None`` if turned off or unusable."""
    configured = os.environ.get(CACHE_DIR_VARIABLE)
    if configured is not None:
        return NlpStore(Path(configured) / "nlp") if configured.strip() else None
    try:
        import platformdirs

        return NlpStore(Path(platformdirs.user_cache_dir("trajgen", appauthor=False)) / "nlp")
    except Exception as error:  # no home folder (a service account): solve without the disk cache
        logger.info("optimal: no user cache folder (%s); NLPs are built in every process", error)
        return None
