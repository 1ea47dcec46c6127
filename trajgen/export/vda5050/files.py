"""VDA 5050 2.1.0 orders of every vehicle as the files of a run, committed all or none.

The files are ``<vehicle name>/order-NNN.json`` and ``manifest.json``; the renderers
(:mod:`trajgen.export.vda5050.messages`) return bytes, and :func:`write_orders` commits every
file of a run together (:func:`~trajgen.export.atomic.commit_files`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from topology.validation import short_repr
from trajgen.errors import OptionError
from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.export.vda5050.messages import render_manifest, render_orders
from trajgen.export.vda5050.options import MANIFEST_NAME, Vda5050Options
from trajgen.export.vda5050.release import order_releases
from trajgen.scenario.naming import check_vehicle_names
from trajgen.verification import VerifiedSchedule, require_verified

__all__ = ["order_files", "order_paths", "write_orders"]


def order_paths(names: Sequence[str], directory: str | Path) -> tuple[Path, ...]:
    """The files every run writes: ``directory/manifest.json``, then each vehicle's first order.

    Raises
    ------
    InputError
        Bad names (also a vehicle named like the manifest), or ``directory`` names no folder.
    """
    names = check_vehicle_names(names)
    for name in names:
        if name.lower() == MANIFEST_NAME.lower():
            raise OptionError(
                f"vehicle name {name!r} is the manifest's file name: expected another name (its orders "
                f"go into a folder of that name beside {MANIFEST_NAME})"
            )
    if not isinstance(directory, (str, Path)) or str(directory) == "":
        raise OptionError(f"VDA 5050 output folder must name a folder, got {short_repr(directory)}")
    directory = Path(directory)
    return (directory / MANIFEST_NAME, *(directory / name / "order-000.json" for name in names))


def order_files(
    verified: VerifiedSchedule, names: Sequence[str], directory: str | Path, *, options: Vda5050Options
) -> dict[Path, bytes]:
    """Every file of a run, rendered: ``directory/<vehicle name>/order-NNN.json`` and ``manifest.json``."""
    order_paths(names, directory)
    releases = order_releases(require_verified(verified, "order_files"))
    messages = render_orders(verified, names, options=options, releases=releases)
    directory = Path(directory)
    files = {directory / message.path: message.data for message in messages}
    files[directory / MANIFEST_NAME] = render_manifest(
        verified, names, messages, options=options, releases=releases
    )
    return files


def write_orders(
    verified: VerifiedSchedule, names: Sequence[str], directory: str | Path, *, options: Vda5050Options
) -> tuple[Path, ...]:
    """Write every VDA 5050 message of a run and its manifest, all or none.

    Parameters
    ----------
    verified : VerifiedSchedule
        From :func:`trajgen.verification.certify`.
    names : sequence of 2 str
        Vehicle names (their folders).
    directory : path
        Created if missing.
    options : Vda5050Options

    Returns
    -------
    tuple of Path
        The files written.

    Raises
    ------
    UnverifiedScheduleError
        ``verified`` is not a VerifiedSchedule.
    InputError
        Bad names, options or output paths; nothing was written.
    """
    check_output_paths(order_paths(names, directory))
    files = order_files(verified, names, directory, options=options)
    check_output_paths(files)
    return commit_files(files)
