"""Rows of fixed-point decimal numbers as ASCII bytes, vectorized with numpy (the CSV writers' formatter).

Every number is written exactly as the per-value Python expression
``f"{round(float(v), places) + 0.0:.{places}f}"`` writes it
(:func:`fixed_point_text`): Python's correctly rounded ``round`` to ``places``
decimals (half to even on the exact binary value), then fixed format, and
never ``-0``. Integer columns are written as ``str(int(v))``.

How, per column of a block of rows:

1. ``y = v * 10**places`` (one rounding) and ``N = rint(y)``. Where ``|v|`` is
   below :func:`exact_limit` (``2**22`` for 9 decimals, ``2**32`` for 6),
   ``|y| < 2**52``, so every half-integer near ``y`` is a double; ``y`` being
   the double nearest the exact product ``P = v * 10**places``, no
   half-integer lies strictly between them, and unless ``y`` is itself a
   half-integer, ``N`` is ``P`` correctly rounded. Where ``y`` is a
   half-integer, the sign of the exact error ``P - y`` (Dekker's two-product)
   says which way ``P`` lies, and a zero error is a true tie: ``rint``'s half
   to even, as ``round`` does.
2. Below that limit ``round`` returns the double nearest ``N * 10**-places``,
   whose spacing is less than ``10**-places``, so it formats back to ``N``:
   the text is ``|N|`` with the decimal mark before its last ``places``
   digits and a ``-`` if ``N < 0`` (a negative value that rounds to 0 gives
   ``0.000...``, as ``+ 0.0`` does).
3. The digits become bytes four at a time: each field and the separator after
   it are right-aligned in a slot of whole 32-bit words, and each word is one
   table look-up of up to four digits of ``|N|`` (the tables hold the digits,
   the decimal mark and the separator at their places); leading zeros and the
   sign come from two more look-ups keyed by the number of integer digits.
   Slot bytes left of the field are ``0``.
4. The words of all columns form one ``(rows, words)`` array; dropping its
   ``0`` bytes leaves the rows.

Values at or above the limit and non-finite ones (no schedule has them) are
written by the Python expression itself, each in its own slot.

The writers hold a limited quantity (a velocity, acceleration or jerk column) to
its limit as written before formatting it (:func:`within_limit`): a value above
the largest number of ``places`` decimals that does not exceed the limit
(:func:`limit_cap`), but within the verifier's tolerance of the limit, becomes
that number; so no number written exceeds its limit once rounded.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["exact_limit", "fixed_point_text", "format_number_rows", "limit_cap", "within_limit"]

#: Byte that fills a slot left of its field; no field or separator contains it.
_PAD = 0
#: Words of four bytes, little-endian: the first character of a word is its lowest byte.
_WORD = np.dtype("<u4")
#: Veltkamp's splitter for doubles (2**27 + 1): x = high + low, each with at most 26 significant bits.
_SPLITTER = 134217729.0


def fixed_point_text(value: float, places: int) -> str:
    """The text of one number: rounded to ``places`` decimals by Python's ``round``, fixed format, no ``-0``.

    The definition that :func:`format_number_rows` reproduces byte for byte.

    Parameters
    ----------
    value : float
    places : int
        Decimal places (>= 0).

    Returns
    -------
    str

    Examples
    --------
    >>> fixed_point_text(2.5e-10, 9), fixed_point_text(-1e-12, 9), fixed_point_text(0.0009765625, 9)
    ('0.000000000', '0.000000000', '0.000976562')
    """
    return f"{round(float(value), places) + 0.0:.{places}f}"  # + 0.0: no "-0"


@functools.cache
def exact_limit(places: int) -> float:
    """Magnitude below which :func:`format_number_rows` writes ``places`` decimals without Python.

    A power of two a binade below the first whose spacing (unit in the last
    place) reaches ``10**-places``: below it ``round(v, places)`` formats back
    to the correctly rounded ``v``, and ``|v| * 10**places < 2**52``.

    Parameters
    ----------
    places : int
        Decimal places, 0 to 15.

    Returns
    -------
    float

    Examples
    --------
    >>> exact_limit(9) == 2.0**22, exact_limit(6) == 2.0**32
    (True, True)
    """
    if not 0 <= places <= 15:
        raise ValueError(f"decimal places must be 0 to 15, got {places!r}")
    return 2.0 ** (math.ceil(53 - places * math.log2(10)) - 2)


def limit_cap(limit: float, places: int) -> float:
    """The largest number of ``places`` decimals whose text, read back, is at most ``limit``.

    Rounding is monotone, so every value at most this cap is written (by :func:`fixed_point_text`)
    as a number at most ``limit``; a limit of more decimals than ``places`` gets the number below it.

    Parameters
    ----------
    limit : float
        A positive limit in the unit the numbers are written in (e.g. mm/s).
    places : int
        Decimal places written (0 to 15).

    Returns
    -------
    float

    Examples
    --------
    >>> limit_cap(1.2, 9), limit_cap(0.1234567896, 9), limit_cap(1000.0, 6)
    (1.2, 0.123456789, 1000.0)
    """
    step = 10.0**-places
    cap = round(float(limit), places)
    while float(fixed_point_text(cap, places)) > limit:
        lower = round(cap - step, places)
        if not lower < cap:  # a limit too large for ``places`` decimals of a double: as close as it gets
            break
        cap = lower
    return cap


def within_limit(values: np.ndarray, limit: float, places: int, *, tolerance: float) -> np.ndarray:
    """``values`` whose magnitude exceeds :func:`limit_cap` by at most ``tolerance``, set to the cap.

    The numbers a limited column is written with: a value above the cap only by the round-off
    the verifier allows (``|v| <= limit * (1 + tolerance)``, plus one unit of the last decimal)
    is written as the cap, with its sign; a value further above it is left as it is (it is no
    round-off: a check of the file reports it).

    Parameters
    ----------
    values : ndarray, shape (n,)
        In the unit of ``limit``.
    limit : float
        The quantity's limit (positive), in that unit.
    places : int
        Decimal places the values are written with.
    tolerance : float
        Relative round-off allowed above the limit (the verifier's: ``1e-6``).

    Returns
    -------
    ndarray, shape (n,)
        A new array if any value changed, else ``values``.

    Examples
    --------
    >>> within_limit(np.array([1.2000000061, -1.2000000061, 0.5, 1.3]), 1.2, 9, tolerance=1e-6)
    array([ 1.2, -1.2,  0.5,  1.3])
    """
    cap = limit_cap(limit, places)
    magnitude = np.abs(values)
    above = (magnitude > cap) & (magnitude <= limit * (1.0 + tolerance) + 10.0**-places)
    if not above.any():
        return values
    return np.where(above, np.copysign(cap, values), values)


def _split(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    scaled = _SPLITTER * values
    high = scaled - (scaled - values)
    return high, values - high


def _product_error(values: np.ndarray, factor: float, products: np.ndarray) -> np.ndarray:
    """``values * factor - products`` exactly, for ``products = fl(values * factor)`` (Dekker)."""
    value_high, value_low = _split(values)
    factor_high, factor_low = _split(np.float64(factor))
    return ((value_high * factor_high - products) + value_high * factor_low + value_low * factor_high) + (
        value_low * factor_low
    )


@dataclass(frozen=True, slots=True)
class _Prepared:
    """One column of a block ready for its digits.

    Attributes: ``magnitude`` ``|N|`` (uint64, shape (n,)), ``negative`` (bool, shape (n,)),
    ``python`` the rows whose text Python wrote and ``texts`` those texts (ASCII, decimal mark
    applied), ``places`` (0 for integers) and ``point`` (whether the text has a decimal mark).
    """

    magnitude: np.ndarray
    negative: np.ndarray
    python: np.ndarray
    texts: tuple[bytes, ...]
    places: int
    point: bool


def _prepare_fixed(values: np.ndarray, places: int, decimal: str) -> _Prepared:
    factor = 10.0**places
    with np.errstate(invalid="ignore", over="ignore"):
        scaled = values * factor
        nearest = np.rint(scaled)
        in_range = np.abs(values) < exact_limit(places)  # NaN compares False
        everywhere = bool(in_range.all())
        distance = np.abs(scaled - nearest)
    halves = np.flatnonzero(distance == 0.5)
    if not everywhere:
        halves = halves[in_range[halves]]
    if halves.size:  # y is a half-integer: the exact product says which way to round
        error = _product_error(values[halves], factor, scaled[halves])
        half = scaled[halves]
        nearest[halves] = np.where(
            error > 0.0, half + 0.5, np.where(error < 0.0, half - 0.5, nearest[halves])
        )
    units = (nearest if everywhere else np.where(in_range, nearest, 0.0)).astype(np.int64)
    python = np.flatnonzero(~in_range) if not everywhere else np.empty(0, dtype=np.intp)
    texts = tuple(
        fixed_point_text(value, places).replace(".", decimal).encode("ascii") for value in values[python]
    )
    return _Prepared(np.abs(units).view(np.uint64), units < 0, python, texts, places, places > 0)


def _prepare_integers(values: np.ndarray) -> _Prepared:
    if values.dtype.kind not in "iu":
        raise TypeError(f"an integer column must have an integer dtype, got {values.dtype}")
    integers = values.astype(np.int64, casting="safe")
    lowest = integers == np.iinfo(np.int64).min  # |lowest| is no int64
    python = np.flatnonzero(lowest)
    texts = tuple(str(int(value)).encode("ascii") for value in integers[python])
    magnitude = np.abs(np.where(lowest, 0, integers)).view(np.uint64)
    return _Prepared(magnitude, integers < 0, python, texts, 0, False)


@dataclass(frozen=True, slots=True)
class _Word:
    """How one word of a field's slot is made.

    ``digits`` digits of ``|N|`` from its digit ``lowest`` up are the index into ``table``; a word
    that can hold integer digits above the units or the sign is ``(table[g] & keep[key]) | sign[key]``,
    ``key = integer digits + (most + 1) * negative``.
    """

    lowest: int
    digits: int
    table: np.ndarray
    keep: np.ndarray | None
    sign: np.ndarray | None


def _shift(position: int) -> int:
    """Bit shift, within its word, of the character ``position`` bytes left of a slot's end."""
    return 8 * (3 - position % 4)


@functools.lru_cache(maxsize=512)
def _layout(
    places: int, point: bool, separator: bytes, mark: int, most: int, signed: bool, words: int
) -> tuple[_Word, ...]:
    """The ``words`` words of a slot, right to left, for fields of at most ``most`` integer digits.

    ``signed``: some field of the block is negative.
    """
    tail = len(separator) + (places + 1 if point else 0)  # separator, fraction digits, decimal mark
    made = []
    for word in range(words):
        fixed = 0
        digit_index = {}  # position -> which digit of |N| it shows
        integer_index = {}  # position -> which integer digit (0: units) or sign it may show
        for position in range(4 * word, 4 * word + 4):
            if position < len(separator):
                fixed |= separator[len(separator) - 1 - position] << _shift(position)
            elif point and position < len(separator) + places:
                digit_index[position] = position - len(separator)
            elif point and position == len(separator) + places:
                fixed |= mark << _shift(position)
            elif position - tail <= most:
                integer_index[position] = position - tail
                if position - tail < most:
                    digit_index[position] = places + position - tail
        lowest = min(digit_index.values(), default=0)
        count = len(digit_index)
        choices = np.arange(10**count)
        table = np.full(choices.size, fixed, dtype=np.int64)
        for position, index in digit_index.items():
            table += ((choices // 10 ** (index - lowest)) % 10 + ord("0")) << _shift(position)
        keep = sign = None
        if any(integer >= 1 for integer in integer_index.values()):
            keys = np.arange(2 * (most + 1))
            digits, negative = keys % (most + 1), keys > most
            keep = np.full(keys.size, 0xFFFFFFFF, dtype=np.int64)
            sign = np.zeros(keys.size, dtype=np.int64)
            for position, integer in integer_index.items():
                if integer >= 1:
                    keep &= np.where(integer >= digits, ~(0xFF << _shift(position)), -1)
                sign |= np.where(negative & (integer == digits), ord("-") << _shift(position), 0)
            keep, sign = keep.astype(_WORD), sign.astype(_WORD)
        made.append(_Word(lowest, count, table.astype(_WORD), keep, sign))
    return tuple(made)


@dataclass(frozen=True, slots=True)
class _Field:
    """One column's slots in a block: its words (right to left), the rows' look-up keys, its text widths.

    ``key`` is ``None`` where every row has one integer digit and none is negative; the text of a
    row with ``d`` integer digits, negative or not, is ``fixed + d + negative`` bytes long (separator
    included).
    """

    words: tuple[_Word, ...]
    key: np.ndarray | None
    most: int
    fixed: int
    separator: bytes

    def width(self, row: int) -> int:
        """Bytes of row ``row``'s text and separator."""
        if self.key is None:
            return self.fixed + 1
        key = int(self.key[row])
        return self.fixed + key % (self.most + 1) + (key > self.most)


def _field(column: _Prepared, separator: bytes, mark: int) -> _Field:
    """How a column's slots are made in this block."""
    most = len(str(int(column.magnitude.max()) // 10**column.places))
    signed = bool(column.negative.any())
    fixed = len(separator) + (column.places + 1 if column.point else 0)
    longest = max((len(text) + len(separator) for text in column.texts), default=0)
    words = _layout(
        column.places,
        column.point,
        separator,
        mark,
        most,
        signed,
        -(-max(fixed + most + signed, longest) // 4),
    )
    if all(word.keep is None for word in words):
        return _Field(words, None, most, fixed, separator)
    key = np.ones(column.magnitude.shape, dtype=np.intp)  # integer digits
    for digit in range(1, most):
        key += column.magnitude >= np.uint64(10 ** (column.places + digit))
    if signed:
        key += (most + 1) * column.negative
    return _Field(words, key, most, fixed, separator)


def _word_values(columns: Sequence[_Prepared], fields: Sequence[_Field]) -> np.ndarray:
    """Every word of every row, shape (words, rows): the slots of all columns left to right."""
    values = np.empty((sum(len(field.words) for field in fields), columns[0].magnitude.size), dtype=_WORD)
    end = 0
    for column, field in zip(columns, fields, strict=True):
        end += len(field.words)
        remaining = column.magnitude
        for number, word in enumerate(field.words):  # right to left
            value = values[end - 1 - number]
            if word.digits:
                power = np.uint64(10**word.digits)
                higher = remaining // power
                np.take(word.table, (remaining - higher * power).view(np.int64), out=value)
                remaining = higher
            else:
                value[...] = word.table[0]
            if word.keep is not None:
                np.bitwise_and(value, word.keep[field.key], out=value)
                np.bitwise_or(value, word.sign[field.key], out=value)
    return values


#: Most runs of rows with one text width per column that a block is written in (else it is compacted).
_MOST_RUNS = 64


def _runs(fields: Sequence[_Field], rows: int) -> list[tuple[int, int, tuple[int, ...]]] | None:
    """Runs ``(start, stop, widths)`` of rows whose every column has one text width; ``None``: too many.

    Also ``None`` where writing a run's words from the right could leave a wrong byte: a row of
    fewer than four bytes after its first field, or a field whose leftmost word reaches past the row's
    start (its padding is overwritten by the fields to its left, written later).
    """
    change = np.zeros(max(rows - 1, 0), dtype=bool)
    for field in fields:
        if field.key is not None:
            change |= field.key[1:] != field.key[:-1]
    starts = np.flatnonzero(change) + 1
    if starts.size >= _MOST_RUNS:
        return None
    bounds = [0, *starts.tolist(), rows]
    runs = []
    for start, stop in itertools.pairwise(bounds):
        widths = tuple(field.width(start) for field in fields)
        if sum(widths) - widths[0] < 4:
            return None
        before = 0
        for width in widths:
            if before and 4 * -(-width // 4) - width > before:
                return None
            before += width
        runs.append((start, stop, widths))
    return runs


#: Bytes before the first row in the buffer of a block written in runs (the first word may reach there).
_MARGIN = 4


def _write_runs(values: np.ndarray, fields: Sequence[_Field], runs) -> bytes:
    """The rows, each run written word by word at the text's own offsets (no padding to drop).

    Each field's words are right-aligned at the field's end; the padding of its leftmost word falls on
    the field to its left, which is written later. The first field's padding falls on the end of the
    row before (or the margin): that end is saved before the first field is written and put back.
    """
    total = sum((stop - start) * sum(widths) for start, stop, widths in runs)
    out = np.empty(_MARGIN + total, dtype=np.uint8)
    slots = np.cumsum([len(field.words) for field in fields])  # the slot ends in ``values``
    base = _MARGIN
    for start, stop, widths in runs:
        count, width = stop - start, sum(widths)
        ends = np.cumsum(widths).tolist()

        def words_at(offset: int, count: int = count, width: int = width) -> np.ndarray:
            return np.ndarray((count,), dtype=_WORD, buffer=out, offset=offset, strides=(width,))

        for index in [*range(len(fields) - 1, 0, -1), 0]:
            if index == 0:
                tail = words_at(base - 4).copy()  # the last four bytes of each row before
            for number in range(-(-widths[index] // 4)):
                words_at(base + ends[index] - 4 * (number + 1))[...] = values[
                    slots[index] - 1 - number, start:stop
                ]
            if index == 0:
                words_at(base - 4)[...] = tail
        base += count * width
    return out[_MARGIN:].tobytes()


def _render(columns: Sequence[_Prepared], separators: Sequence[bytes], mark: int) -> bytes:
    rows = columns[0].magnitude.size
    if rows == 0:
        return b""
    fields = [_field(column, separator, mark) for column, separator in zip(columns, separators, strict=True)]
    values = _word_values(columns, fields)
    if not any(column.texts for column in columns):
        runs = _runs(fields, rows)
        if runs is not None:
            return _write_runs(values, fields, runs)
    block = np.ascontiguousarray(values.T)  # slots left to right, row by row; padding dropped below
    end = 0
    for column, field in zip(columns, fields, strict=True):
        end += len(field.words)
        for row, text in zip(column.python.tolist(), column.texts, strict=True):
            slot = (text + field.separator).rjust(4 * len(field.words), bytes([_PAD]))
            block[row, end - len(field.words) : end] = np.frombuffer(slot, dtype=_WORD)
    text = block.view(np.uint8)
    return text[text != _PAD].tobytes()


def format_number_rows(
    columns: Sequence[tuple[np.ndarray, int | None]], separators: Sequence[str], *, decimal: str = "."
) -> bytes:
    r"""Rows of numbers as ASCII text: per row, each column's number followed by its separator.

    Parameters
    ----------
    columns : sequence of (ndarray, int or None)
        Each column's values, shape (n,) (one n for all), and its decimal places (0 to 15): a float
        column is written as :func:`fixed_point_text` writes each value; ``None`` marks an integer
        column (a signed integer dtype, or an unsigned one of up to 32 bits), written as ``str``.
    separators : sequence of str
        The text after each column's number, one per column: e.g. ``;`` after every column but the
        last and ``\r\n`` after the last. ASCII, without NUL.
    decimal : str
        The decimal mark, ``.`` or ``,`` (in place of the ``.`` of :func:`fixed_point_text`).

    Returns
    -------
    bytes
        ``n`` rows: the bytes of joining the per-value texts in Python.

    Examples
    --------
    >>> t = np.array([0.0, 0.01, 2.5])
    >>> v = np.array([-1e-12, -0.0009765625, 1234.5678901234])
    >>> format_number_rows([(t, 6), (v, 9), (np.array([0, 1, -2]), None)], [";", ";", "\r\n"], decimal=",")
    b'0,000000;0,000000000;0\r\n0,010000;-0,000976562;1\r\n2,500000;1234,567890123;-2\r\n'
    """
    if len(columns) == 0 or len(columns) != len(separators):
        raise ValueError(
            f"expected at least one column and a separator per column, got {len(columns)} column(s) "
            f"and {len(separators)} separator(s)"
        )
    if decimal not in (".", ","):
        raise ValueError(f"decimal mark must be '.' or ',', got {decimal!r}")
    ends = tuple(separator.encode("ascii") for separator in separators)
    if any(_PAD in end for end in ends):
        raise ValueError("a separator must not contain NUL")
    arrays = [np.asarray(values) for values, _ in columns]
    if any(array.ndim != 1 or array.shape != arrays[0].shape for array in arrays):
        raise ValueError(f"columns must be 1-D and of one length, got shapes {[a.shape for a in arrays]}")
    prepared = [
        _prepare_integers(array)
        if places is None
        else _prepare_fixed(array.astype(np.float64, copy=False), places, decimal)
        for array, (_, places) in zip(arrays, columns, strict=True)
    ]
    return _render(prepared, ends, ord(decimal))
