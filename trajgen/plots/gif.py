"""Animated GIF bytes from RGB frames, encoded one frame at a time (memory independent of the count).

Pillow's own multi-frame writer keeps every frame until the end; here each
frame is compared with the previous frame only, the rectangle holding its
changes is mapped to one shared palette (the samples' 255 most frequent
colours exactly, others to the nearest), pixels that did not change become
the transparent index 255, and the rectangle is encoded at once (Pillow's LZW
encoder, by saving it as a one-frame GIF and keeping its image data). So at
most two frames are held, whatever the number of frames.
"""

from __future__ import annotations

import io
import struct
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from trajgen.errors import InputError

if TYPE_CHECKING:  # Pillow is imported when a GIF is made, not with the package
    from PIL import Image

__all__ = ["GIF_DELAY_UNIT_MS", "encode_gif", "gif_bytes"]

#: GIF frame delays are whole hundredths of a second.
GIF_DELAY_UNIT_MS = 10
#: Palette index of pixels a frame leaves as the previous frame showed them.
_TRANSPARENT = 255


def _image_data(frame: Image.Image) -> tuple[int, bytes]:
    """Interlace flag and LZW image data (code size byte, sub-blocks, terminator) of a P-mode image.

    Saved as a one-frame GIF by Pillow, then the blocks after its image descriptor are kept.
    """
    buffer = io.BytesIO()
    frame.save(buffer, format="GIF", interlace=False, optimize=False)
    data = buffer.getvalue()
    position = 13  # header (6) + logical screen descriptor (7)
    packed = data[10]
    if packed & 0x80:  # global colour table
        position += 3 * (2 << (packed & 0x07))
    while data[position] == 0x21:  # extension blocks: skip their sub-blocks
        position += 2
        while data[position]:
            position += data[position] + 1
        position += 1
    if data[position] != 0x2C:
        raise InputError(f"Pillow wrote no image descriptor where expected (byte {data[position]:#x})")
    flags = data[position + 9]
    position += 10
    if flags & 0x80:  # local colour table
        position += 3 * (2 << (flags & 0x07))
    end = position + 1  # LZW minimum code size
    while data[end]:
        end += data[end] + 1
    return flags & 0x40, data[position : end + 1]


def _pack(rgb: np.ndarray) -> np.ndarray:
    """RGB triples, shape (..., 3) uint8, as one integer each, shape (...)."""
    rgb = rgb.astype(np.uint32)
    return (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]


class _Palette:
    """Up to 255 colours and the exact lookup of a frame's pixels in them (nearest colour if absent)."""

    def __init__(self, packed: np.ndarray) -> None:
        self.colours = np.stack([(packed >> 16) & 255, (packed >> 8) & 255, packed & 255], 1).astype(np.int32)
        self.order = np.argsort(packed)
        self.sorted = packed[self.order]
        #: the global colour table: 256 entries of 3 bytes
        self.table = self.colours.astype(np.uint8).tobytes() + b"\0" * (3 * (256 - len(packed)))
        #: colours not in the table met so far (sorted) and the index of the nearest one of each: frame
        #: after frame the same edges of text and lines come back
        self.seen = np.zeros(0, dtype=packed.dtype)
        self.seen_index = np.zeros(0, dtype=np.intp)

    def indices(self, packed: np.ndarray) -> np.ndarray:
        """Palette index of each pixel, uint8, of the shape of ``packed`` (colours of :func:`_pack`)."""
        flat = packed.ravel()
        position = np.minimum(np.searchsorted(self.sorted, flat), len(self.sorted) - 1)
        found = self.sorted[position] == flat
        indices = self.order[position]
        if not found.all():  # colours not in the table: the nearest one (few distinct colours)
            missing, inverse = np.unique(flat[~found], return_inverse=True)
            indices[~found] = self._nearest(missing)[inverse.ravel()]
        return indices.astype(np.uint8).reshape(packed.shape)

    def _nearest(self, missing: np.ndarray) -> np.ndarray:
        """The index of the nearest table colour to each of ``missing`` (sorted, distinct), remembered."""
        at = np.minimum(np.searchsorted(self.seen, missing), max(self.seen.size - 1, 0))
        new = missing[~(self.seen[at] == missing)] if self.seen.size else missing
        if new.size:
            wanted = np.stack([(new >> 16) & 255, (new >> 8) & 255, new & 255], 1).astype(np.int32)
            distance = ((wanted[:, None, :] - self.colours[None, :, :]) ** 2).sum(axis=2)
            seen = np.concatenate([self.seen, new])
            order = np.argsort(seen, kind="stable")
            self.seen = seen[order]
            self.seen_index = np.concatenate([self.seen_index, np.argmin(distance, axis=1)])[order]
            at = np.searchsorted(self.seen, missing)
        return self.seen_index[at]


def _delay_units(delay_ms: float) -> int:
    units = round(delay_ms / GIF_DELAY_UNIT_MS)
    if not 1 <= units <= 0xFFFF:
        raise InputError(
            f"GIF frame delay {delay_ms!r} ms is out of range: expected 10 ms to {0xFFFF * 10} ms"
        )
    return units


def gif_bytes(
    frames: Iterable[np.ndarray], *, delays_ms: Sequence[float], palette_samples: Sequence[np.ndarray]
) -> bytes:
    """Encode RGB frames as a looping animated GIF.

    Parameters
    ----------
    frames : iterable of ndarray, each shape (height, width, 3), uint8
        The frames in order, all of one size; consumed one at a time.
    delays_ms : sequence of float, shape (n,)
        How long each frame is shown, milliseconds (rounded to 10 ms, at least 10 ms).
    palette_samples : sequence of ndarray, each shape (height, width, 3), uint8
        Frames whose 255 most frequent colours make the shared palette (e.g. the
        first, the last and one in between); other colours become the nearest of them.

    Returns
    -------
    bytes
        The GIF (89a, looping forever).

    Raises
    ------
    InputError
        No frames, frames of different sizes, or more frames than delays.
    """
    samples = [np.asarray(sample, dtype=np.uint8) for sample in palette_samples]
    if not samples:
        raise InputError("a GIF palette needs at least one sample frame, got none")
    # the samples' 255 most frequent colours, exactly (white stays white); index 255 is kept for
    # "unchanged" (transparent) pixels
    packed, counts = np.unique(_pack(np.concatenate([s.reshape(-1, 3) for s in samples])), return_counts=True)
    palette = _Palette(packed[np.argsort(-counts, kind="stable")[:_TRANSPARENT]])
    out = io.BytesIO()
    previous: np.ndarray | None = None
    count = 0
    for count, rgb in enumerate(frames, start=1):
        if count > len(delays_ms):
            raise InputError(f"GIF: more frames than the {len(delays_ms)} delays given")
        array = np.asarray(rgb, dtype=np.uint8)
        if array.ndim != 3 or array.shape[2] != 3:
            raise InputError(f"GIF frames must be RGB arrays of shape (height, width, 3), got {array.shape}")
        height, width = array.shape[:2]
        packed = _pack(array)
        if previous is None:
            out.write(b"GIF89a" + struct.pack("<HHBBB", width, height, 0xF7, 0, 0) + palette.table)
            out.write(b"\x21\xff\x0bNETSCAPE2.0\x03\x01\x00\x00\x00")  # loop forever
            top, bottom, left, right = 0, height, 0, width
            part = palette.indices(packed)
        else:
            if packed.shape != previous.shape:
                raise InputError(f"GIF frames must all be {previous.shape} pixels, got {packed.shape}")
            changed = packed != previous
            rows, columns = np.flatnonzero(changed.any(axis=1)), np.flatnonzero(changed.any(axis=0))
            if rows.size:
                top, bottom, left, right = rows[0], rows[-1] + 1, columns[0], columns[-1] + 1
            else:  # nothing changed: one transparent pixel carries the delay
                top, bottom, left, right = 0, 1, 0, 1
            window = (slice(top, bottom), slice(left, right))
            moved = changed[window]
            # only the changed pixels are looked up: a clock and a bar span the frame, but change little
            part = np.full(moved.shape, _TRANSPARENT, dtype=np.uint8)
            part[moved] = palette.indices(packed[window][moved])
        from PIL import Image

        image = Image.frombytes("P", (part.shape[1], part.shape[0]), np.ascontiguousarray(part).tobytes())
        image.putpalette(palette.table)
        interlace, data = _image_data(image)
        delay = _delay_units(delays_ms[count - 1])
        # graphic control: keep the frame under the next one (disposal 1), index 255 transparent
        out.write(b"\x21\xf9\x04" + struct.pack("<BHB", 0x05, delay, _TRANSPARENT) + b"\0")
        out.write(b"\x2c" + struct.pack("<HHHHB", left, top, right - left, bottom - top, interlace))
        out.write(data)
        previous = packed
    if previous is None:
        raise InputError("a GIF needs at least one frame, got none")
    out.write(b"\x3b")
    return out.getvalue()


def encode_gif(animation) -> bytes:
    """An :class:`~trajgen.plots.animation.Animation` as a looping GIF, a frame drawn at a time."""
    return gif_bytes(
        animation.frames(), delays_ms=animation.delays_ms, palette_samples=animation.palette_samples
    )
