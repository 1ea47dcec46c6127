"""Input files read whole but bounded: regular files only, refused unread when too large."""

from __future__ import annotations

import os
import stat
from dataclasses import dataclass
from pathlib import Path

from trajgen.errors import InputError

__all__ = ["FileKind", "file_label", "read_bounded"]


def file_label(path: str | Path) -> str:
    """The path for messages: at most 120 characters (a long one is cut with ``...``)."""
    text = str(path)
    return text if len(text) <= 120 else text[:117] + "..."


@dataclass(frozen=True, slots=True)
class FileKind:
    """What kind of input file is read, for its messages.

    Parameters
    ----------
    name : str
        The kind with its article, e.g. ``"a scenario file"``.
    format : str
        The expected format, e.g. ``"a scenario TOML file"``.
    most_bytes : int
        The largest file read, bytes.
    error : type
        The InputError subclass raised.
    """

    name: str
    format: str
    most_bytes: int
    error: type[InputError] = InputError


def read_bounded(path: Path, label: str, kind: FileKind) -> bytes:
    """The bytes of ``path``, a regular file of at most ``kind.most_bytes`` bytes.

    Parameters
    ----------
    path : Path
    label : str
        How messages name the file (:func:`file_label`).
    kind : FileKind

    Raises
    ------
    InputError
        ``kind.error``: not a regular file (a folder, ``/dev/zero``), larger than
        ``kind.most_bytes`` (refused unread, also if it grows while read), or unreadable.
    """
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode):
            raise kind.error(f"{label}: is not a regular file: expected {kind.format}")
        if info.st_size > kind.most_bytes:
            raise kind.error(
                f"{label}: is {info.st_size:,} bytes: "
                f"expected {kind.name} of at most {kind.most_bytes:,} bytes"
            )
        with open(path, "rb") as stream:
            data = stream.read(kind.most_bytes + 1)
    except OSError as error:
        the = kind.name.removeprefix("a ").removeprefix("an ")
        raise kind.error(f"{label}: cannot read the {the}: {error.strerror or error}") from None
    if len(data) > kind.most_bytes:
        raise kind.error(f"{label}: is longer than {kind.most_bytes:,} bytes: expected {kind.name}")
    return data
