"""All files of one run committed together or not at all, also across processes and crashes.

A commit locks every output folder (``flock`` on the folder itself, in one
order, so concurrent runs take turns), writes every file to a hidden
temporary file beside its target and flushes it to disk, keeps a hidden
backup (a hard link) of each file it will replace, writes a journal of what
it is about to do into each folder, then renames the files into place. Once
all renames are done the journals are removed: that is the commit. A failure
before that puts every target back as it was; a crash (even SIGKILL) is
undone by the next commit into any of those folders, or by
:func:`recover_folder`, which finds the journal and restores the backups.
Hidden files a crashed run left (``*.trajgen-tmp``, ``*.trajgen-bak``) are
removed then too.

``flock`` is POSIX (Linux, macOS): the module imports anywhere, and a commit on a system
without it is refused with an :class:`~trajgen.errors.OutputError` saying so.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import shutil
import sys
import tempfile
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from trajgen.errors import OutputError

logger = logging.getLogger(__name__)

__all__ = ["JOURNAL_NAME", "check_output_paths", "commit_files", "recover_folder"]

#: Name of the journal an unfinished commit leaves in each of its folders.
JOURNAL_NAME = ".trajgen-journal"
_TMP_SUFFIX = ".trajgen-tmp"
_BAK_SUFFIX = ".trajgen-bak"


def _short(path: Path) -> str:
    text = str(path)
    return text if len(text) <= 120 else text[:117] + "..."


def check_output_paths(paths) -> tuple[Path, ...]:
    """Check that each path can become a file, before anything is computed for it.

    Each path must not be a folder and must lie below folders (existing or to be made); and each
    folder must take new files: a probe file is created and removed at once in the folder, or in
    its nearest existing ancestor for a folder the commit will make (a read-only or immutable
    folder, ``/proc``, a full quota are refused here, not after a solve).

    Raises
    ------
    OutputError
        A target is a folder, a parent is a file, a path is empty or given twice, or a folder
        takes no new file (naming the path asked for and the reason).
    """
    try:
        checked = _check_output_paths(paths)
    except OSError as error:  # a name the file system refuses (too long, ...)
        where = _short(Path(error.filename)) if error.filename else "an output path"
        raise OutputError(f"cannot use output path {where!r}: {error.strerror or error}") from None
    probed: set[str] = set()
    for path in checked:
        folder = next((p for p in path.parents if p.exists()), Path("."))
        if str(folder) not in probed:
            _probe(folder, path)
            probed.add(str(folder))
    return checked


def _asked_for(filename: str | os.PathLike, paths: Sequence[Path]) -> Path:
    """The path asked for that ``filename`` stands for.

    A hidden temporary or backup names its file; the commit's journal in a folder, the first file
    asked for in that folder.
    """
    name = Path(filename)
    beside = [path for path in paths if path.parent == name.parent]
    for path in beside:
        hidden = name.name.startswith(f".{path.name}.") and name.name.endswith((_TMP_SUFFIX, _BAK_SUFFIX))
        if name == path or hidden:
            return path
    return beside[0] if beside and name.name.startswith(JOURNAL_NAME) else name


def _probe(folder: Path, path: Path) -> None:
    """Create and remove a hidden file in ``folder``, which is to hold ``path`` (or its folders)."""
    try:
        # the commits' temporary suffix: a probe a crash left behind goes with the next commit's recovery
        handle, probe = tempfile.mkstemp(prefix=".trajgen-probe.", suffix=_TMP_SUFFIX, dir=folder)
        os.close(handle)
        with contextlib.suppress(FileNotFoundError):  # a concurrent commit's recovery took it already
            os.unlink(probe)
    except OSError as error:
        raise OutputError(
            f"cannot write {_short(path)!r}: folder {_short(folder)!r} takes no new file "
            f"({error.strerror or error}); expected a writable folder"
        ) from None


def _check_output_paths(paths) -> tuple[Path, ...]:
    checked: list[Path] = []
    seen: set[tuple[str, str]] = set()
    for given in paths:
        path = Path(given)
        if not path.name or path.name in (".", ".."):
            raise OutputError(f"output file path {_short(path)!r} names no file")
        # the same file however spelled: through links, and on file systems that ignore case
        key = (os.path.realpath(path.parent), path.name.casefold())
        if key in seen:
            raise OutputError(f"output file {_short(path)!r} is asked for twice in one run")
        seen.add(key)
        if path.is_dir():
            raise OutputError(f"output file {_short(path)!r} exists as a folder: expected a file or nothing")
        for parent in path.parents:
            if parent.exists():
                if not parent.is_dir():
                    raise OutputError(f"output folder {_short(parent)!r} exists and is not a folder")
                break
        checked.append(path)
    return tuple(checked)


def _make_folders(folder: Path, created: list[Path]) -> None:
    """``mkdir -p folder``, recording each folder made (outermost first)."""
    missing = []
    for candidate in (folder, *folder.parents):
        if candidate.exists():
            break
        missing.append(candidate)
    for candidate in reversed(missing):
        candidate.mkdir()
        created.append(candidate)


def _sync_folder(folder: Path) -> None:
    with contextlib.suppress(OSError):  # not every file system lets a folder be opened for fsync
        handle = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(handle)
        finally:
            os.close(handle)


def _read_umask() -> int:
    """The process's umask, read without changing it where the system tells it (Linux)."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)  # elsewhere: read it once, at import, before any thread writes files
    os.umask(mask)
    return mask


#: Permissions of the files written: what a plain ``open`` would give them.
_FILE_MODE = 0o666 & ~_read_umask()


#: Marks an exhausted payload while staging.
_EXHAUSTED = object()


def _stage(
    paths: Sequence[Path],
    payloads: Sequence[bytes | Iterable[bytes]],
    mode: int,
    staged: list[tuple[str, Path]],
) -> None:
    """Write each payload to a hidden temporary file beside its path and flush them all to disk.

    Chunks are taken from the payloads in turn, one of each at a time, so that payloads made from one
    source in step (both vehicles' CSV profiles, :func:`trajgen.export.csv.profile_chunk_pair`) are
    consumed in step. Each temporary file is appended to ``staged`` as soon as it exists: the caller
    removes them if anything fails.
    """
    streams = []
    try:
        for path in paths:
            handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=_TMP_SUFFIX, dir=path.parent)
            staged.append((temporary, path))
            streams.append(os.fdopen(handle, "wb"))
            os.chmod(temporary, mode)  # mkstemp makes 0600; the files are for other tools too
        pending = [
            (stream, iter([data] if isinstance(data, bytes | bytearray) else data))
            for stream, data in zip(streams, payloads, strict=True)
        ]
        while pending:
            still = []
            for stream, chunks in pending:
                chunk = next(chunks, _EXHAUSTED)
                if chunk is not _EXHAUSTED:
                    stream.write(chunk)
                    still.append((stream, chunks))
            pending = still
        for stream in streams:
            stream.flush()
            os.fsync(stream.fileno())
    finally:
        for stream in streams:
            stream.close()


def _keep_previous(path: Path) -> Path | None:
    """A hidden copy of what ``path`` is now (a hard link where possible; a link stays a link)."""
    if not os.path.lexists(path):
        return None
    backup = path.with_name(f".{path.name}.{os.urandom(16).hex()}{_BAK_SUFFIX}")
    try:
        os.link(path, backup, follow_symlinks=False)
    except OSError:
        if path.is_symlink():
            os.symlink(os.readlink(path), backup)
        else:
            shutil.copy2(path, backup)
    return backup


def _write_journal(
    folder: str, entries: list[tuple[Path, Path | None]], folders: list[str], key: str
) -> None:
    """Record, durably, which targets of ``folder`` a commit replaces and where their backups are."""
    record = {
        "commit": key,
        "primary": folders[0],
        "folders": folders,
        "entries": [[path.name, None if backup is None else backup.name] for path, backup in entries],
    }
    journal = Path(folder) / JOURNAL_NAME
    temporary = journal.with_name(f"{JOURNAL_NAME}.{key}{_TMP_SUFFIX}")
    try:
        with open(temporary, "w", encoding="utf-8") as stream:
            json.dump(record, stream)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, journal)
    except BaseException:
        temporary.unlink(missing_ok=True)  # a journal that was never in place leaves nothing behind
        raise
    _sync_folder(Path(folder))


def _plain(name: object, suffix: str = "") -> bool:
    return (
        isinstance(name, str)
        and name not in ("", ".", "..")
        and "/" not in name
        and os.sep not in name
        and "\0" not in name
        and name.endswith(suffix)
    )


def _read_journal(folder: str) -> dict | None:
    """The journal an unfinished commit left in ``folder``, checked; ``None`` if there is none.

    Raises
    ------
    OutputError
        The journal is damaged or names files outside its folder: nothing is touched.
    """
    path = Path(folder) / JOURNAL_NAME
    try:
        with open(path, encoding="utf-8") as stream:
            record = json.load(stream)
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as error:
        raise OutputError(f"{_short(path)!r} is damaged ({error}): restore its folder by hand") from None
    entries = record.get("entries") if isinstance(record, dict) else None
    folders = record.get("folders") if isinstance(record, dict) else None
    valid = (
        isinstance(entries, list)
        and isinstance(folders, list)
        and all(isinstance(f, str) and os.path.isabs(f) for f in folders)
        and isinstance(record.get("commit"), str)
        and isinstance(record.get("primary"), str)
        and all(
            isinstance(e, list)
            and len(e) == 2
            and _plain(e[0])
            and (e[1] is None or (_plain(e[1], _BAK_SUFFIX) and e[1].startswith(".")))
            for e in entries
        )
    )
    if not valid:
        raise OutputError(f"{_short(path)!r} is not a trajgen commit journal: restore its folder by hand")
    return record


def _committed(record: dict) -> bool:
    """Whether the commit of ``record`` reached its commit point (its primary journal is gone)."""
    primary = _read_journal(record["primary"]) if os.path.isdir(record["primary"]) else None
    return primary is None or primary.get("commit") != record["commit"]


def _finish(folder: str) -> None:
    """A commit that reached its commit point: its new files stand; drop the journal (backups go later)."""
    (Path(folder) / JOURNAL_NAME).unlink(missing_ok=True)
    _sync_folder(Path(folder))


def _undo(folder: str, record: dict) -> None:
    """Put every target of an unfinished commit in ``folder`` back as it was."""
    base = Path(folder)
    for name, backup in record.get("entries", []):
        target = base / name
        if backup is not None:
            if os.path.lexists(base / backup):
                os.replace(base / backup, target)
        else:
            target.unlink(missing_ok=True)
    (base / JOURNAL_NAME).unlink(missing_ok=True)
    _sync_folder(base)


def _remove_leftovers(folder: str) -> None:
    """Remove hidden temporary files and backups that a crashed commit left (call with the lock held)."""
    for entry in os.scandir(folder):
        if entry.name.startswith(".") and entry.name.endswith((_TMP_SUFFIX, _BAK_SUFFIX)):
            with contextlib.suppress(FileNotFoundError):
                os.unlink(entry.path)


class _FolderLocks:
    """Exclusive locks on folders, taken in one order; also on every folder an unfinished commit names."""

    def __init__(self, folders) -> None:
        self.folders = sorted(set(folders))
        self.handles: list[int] = []

    def __enter__(self) -> _FolderLocks:
        try:
            import fcntl
        except ImportError:  # Windows: no flock on folders
            raise OutputError(
                f"committing files on {sys.platform!r}: this needs POSIX folder locks (flock): "
                "expected Linux or macOS"
            ) from None
        while True:
            try:
                for folder in self.folders:
                    handle = os.open(folder, os.O_RDONLY)
                    self.handles.append(handle)
                    fcntl.flock(handle, fcntl.LOCK_EX)
                named = {
                    f
                    for folder in self.folders
                    if (record := _read_journal(folder))
                    for f in record["folders"]
                }
            except BaseException:
                self._release()
                raise
            named = {f for f in named if os.path.isdir(f)}
            if named <= set(self.folders):
                return self
            self._release()
            self.folders = sorted(set(self.folders) | named)

    def _release(self) -> None:
        for handle in self.handles:
            os.close(handle)  # closing the descriptor releases its flock
        self.handles = []

    def __exit__(self, *exc) -> None:
        self._release()

    def recover(self) -> None:
        """Finish or undo every interrupted commit in the locked folders; remove what crashed runs left.

        A commit whose primary journal is gone had reached its commit point: its
        other folders keep the new files. Otherwise every folder is put back.
        """
        records = {folder: _read_journal(folder) for folder in self.folders}
        decisions = {
            folder: _committed(record) and folder != record["primary"]
            for folder, record in records.items()
            if record is not None
        }
        for folder, finished in decisions.items():
            if finished:
                _finish(folder)
            else:
                _undo(folder, records[folder])
        for folder in self.folders:
            _remove_leftovers(folder)


def recover_folder(folder: str | Path) -> None:
    """Undo an unfinished commit that a crashed run left in ``folder`` (and in its other folders).

    Commits do this themselves for every folder they write to; call it to
    tidy a folder that no later run writes to.
    """
    if not os.path.isdir(folder):
        raise OutputError(f"{_short(Path(folder))!r} is not a folder: nothing to recover")
    with _FolderLocks([os.path.realpath(folder)]) as locks:
        locks.recover()


def _replace_all(staged: list[tuple[str, Path]]) -> None:
    """Rename every staged file onto its target, journalled; on failure put every target back as it was."""
    backups = [(path, _keep_previous(path)) for _, path in staged]
    key = os.urandom(16).hex()
    by_folder: dict[str, list[tuple[Path, Path | None]]] = {}
    for path, backup in backups:
        by_folder.setdefault(os.path.realpath(path.parent), []).append((path, backup))
    folders = sorted(by_folder)
    done: list[tuple[Path, Path | None]] = []
    try:
        for folder, entries in by_folder.items():
            _write_journal(folder, entries, folders, key)
        for (temporary, path), (_, backup) in zip(staged, backups, strict=True):
            os.replace(temporary, path)
            done.append((path, backup))
        # the commit point: the primary (first) folder's journal goes first; from then on the new
        # files stand, and recovery finishes the other folders instead of undoing them
        for folder in folders:
            (Path(folder) / JOURNAL_NAME).unlink()
    except BaseException:
        for path, previous in reversed(done):
            if previous is not None:
                os.replace(previous, path)
            else:
                path.unlink(missing_ok=True)
        for folder in folders:
            (Path(folder) / JOURNAL_NAME).unlink(missing_ok=True)
        for _, previous in backups:
            if previous is not None:
                previous.unlink(missing_ok=True)
        raise
    for _, previous in backups:
        if previous is not None:
            previous.unlink(missing_ok=True)


def commit_files(contents: Mapping[Path | str, bytes | Iterable[bytes]]) -> tuple[Path, ...]:
    """Write several files so that either all appear complete or nothing changes.

    Parameters
    ----------
    contents : dict of path to bytes or iterable of bytes
        Every file of the run and its content, whole or as chunks streamed to
        disk one at a time (memory stays bounded), a chunk of each file in
        turn. Missing folders are made.

    Returns
    -------
    tuple of Path
        The files written, in the order given.

    Raises
    ------
    OutputError
        A target cannot be a file (see :func:`check_output_paths`) or cannot be written.
    """
    try:
        paths = check_output_paths(contents)
    except OSError as error:
        raise OutputError(
            f"cannot use output path {_short(Path(error.filename or ''))!r}: {error.strerror}"
        ) from None
    data = [contents[key] for key in contents]
    created: list[Path] = []
    staged: list[tuple[str, Path]] = []
    succeeded = False
    try:
        try:
            for path in paths:
                _make_folders(path.parent, created)
            with _FolderLocks(os.path.realpath(path.parent) for path in paths) as locks:
                locks.recover()
                _stage(paths, data, _FILE_MODE, staged)
                _replace_all(staged)
                succeeded = True
                for folder in locks.folders:
                    _sync_folder(Path(folder))
        except OSError as error:
            where = _short(_asked_for(error.filename, paths)) if error.filename else "the output folder"
            raise OutputError(f"cannot write {where!r}: {error.strerror or error}") from error
    finally:
        if not succeeded:
            for temporary, _ in staged:
                try:
                    os.unlink(temporary)
                except FileNotFoundError:
                    pass
                except OSError as error:  # a folder turned read-only: the next commit's recovery removes it
                    logger.warning("could not remove the temporary file %s: %s", temporary, error.strerror)
            for folder in reversed(created):
                with contextlib.suppress(OSError):
                    folder.rmdir()
    return paths
