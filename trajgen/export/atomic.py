"""All files of one run committed together or not at all.

Every file is first written to a temporary file beside its target and
flushed to disk; only then are the targets replaced, one rename each. If any
step fails, the files already replaced get their previous content back, new
files and the folders made for them are removed, and no temporary file is
left: the output folders look as they did before the run.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
import uuid
from collections.abc import Iterable, Mapping
from pathlib import Path

from trajgen.errors import OutputError

__all__ = ["check_output_paths", "commit_files"]


def _short(path: Path) -> str:
    text = str(path)
    return text if len(text) <= 120 else text[:117] + "..."


def check_output_paths(paths) -> tuple[Path, ...]:
    """Check that each path can become a file: not a folder, below folders (existing or to be made).

    Raises
    ------
    OutputError
        A target is a folder, a parent is a file, or a path is empty or given twice.
    """
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


def _stage(path: Path, data: bytes | Iterable[bytes], mode: int) -> str:
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        os.chmod(temporary, mode)  # mkstemp makes 0600; the files are for other tools too
        with os.fdopen(handle, "wb") as stream:
            for chunk in [data] if isinstance(data, bytes | bytearray) else data:
                stream.write(chunk)
            stream.flush()
            os.fsync(stream.fileno())
    except BaseException:
        os.unlink(temporary)
        raise
    return temporary


def _keep_previous(path: Path) -> Path | None:
    """A hidden copy of what ``path`` is now (a hard link where possible; a link stays a link)."""
    if not os.path.lexists(path):
        return None
    backup = path.with_name(f".{path.name}.{uuid.uuid4().hex}.bak")
    try:
        os.link(path, backup, follow_symlinks=False)
    except OSError:
        if path.is_symlink():
            os.symlink(os.readlink(path), backup)
        else:
            shutil.copy2(path, backup)
    return backup


def _replace_all(staged: list[tuple[str, Path]]) -> None:
    """Rename every staged file onto its target; on failure put every target back as it was."""
    done: list[tuple[Path, Path | None]] = []
    backup = None
    try:
        for temporary, path in staged:
            backup = _keep_previous(path)
            os.replace(temporary, path)
            done.append((path, backup))
            backup = None
    except BaseException:
        if backup is not None:
            backup.unlink(missing_ok=True)
        for path, previous in reversed(done):
            if previous is not None:
                os.replace(previous, path)
            else:
                path.unlink(missing_ok=True)
        raise
    for _, previous in done:
        if previous is not None:
            previous.unlink(missing_ok=True)


def commit_files(contents: Mapping[Path | str, bytes | Iterable[bytes]]) -> tuple[Path, ...]:
    """Write several files so that either all appear complete or nothing changes.

    Parameters
    ----------
    contents : mapping of path to bytes or iterable of bytes
        Every file of the run and its content, whole or as chunks streamed to
        disk one at a time (memory stays bounded). Missing folders are made.

    Returns
    -------
    tuple of Path
        The files written, in the order given.

    Raises
    ------
    OutputError
        A target cannot be a file (see :func:`check_output_paths`) or cannot be written.
    """
    paths = check_output_paths(contents)
    data = [contents[key] for key in contents]
    created: list[Path] = []
    staged: list[tuple[str, Path]] = []
    succeeded = False
    try:
        try:
            for path, payload in zip(paths, data, strict=True):
                _make_folders(path.parent, created)
                staged.append((_stage(path, payload, _FILE_MODE), path))
            _replace_all(staged)
        except OSError as error:
            where = _short(Path(error.filename)) if error.filename else "the output folder"
            raise OutputError(f"cannot write {where!r}: {error.strerror or error}") from error
        succeeded = True
        for folder in {path.parent for path in paths}:
            _sync_folder(folder)
    finally:
        if not succeeded:
            for temporary, _ in staged:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(temporary)
            for folder in reversed(created):
                with contextlib.suppress(OSError):
                    folder.rmdir()
    return paths
