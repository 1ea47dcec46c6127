"""The units an optimal-control problem is solved in: times and distances of the problem's own size.

In seconds and metres a long track's NLP is badly scaled: positions and segment durations run to
a thousand while velocities and accelerations stay near one, and the interior-point solver's
step control (its tolerances, its initial barrier parameter, its bound push) sees other numbers
than on a short track. fatrop then takes 71 iterations on the first grid of the
1000/800/1200 m track where a short one takes 20, and how many depends on the CasADi release.
The problem is solved instead in a time unit that grows with the class's lower bound
(:data:`TIME_SHARE`): a swap on 10 m legs and a crossing of 1,000 m legs look alike to the
solver.

The transcription is unit-free: every constant of it is a parameter or a bound (the shortest
segment, the braking rule's margin and its curvature term), so scaling changes the numbers
passed to the compiled NLP only, never its structure. :class:`ProblemUnits` converts the
variables, bounds and parameters in, and the solution out.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from trajgen.methods.optimal.phases import NlpShape, stages

__all__ = ["TIME_SHARE", "ProblemUnits", "variable_dimensions"]

#: The time unit is the power of two at or below this share of the class's lower bound, and never
#: below a second: problems up to about a minute are solved in seconds and metres as they are
#: (their numbers are near one already), longer ones in units that bring them back there. The
#: length unit is the distance a vehicle covers in the time unit at 1 m/s, so velocities keep
#: their values. Powers of two make the conversion exact in floating point. On the
#: 1000/800/1200 m track (time unit 32 s) fatrop's first pass takes 21 iterations instead of 71
#: and the slower class 43 instead of 209; the makespan is 0.0001 % over the S-curve bound.
TIME_SHARE = 0.03

#: Powers of (length, time) of a node state: s, v, a of each vehicle, the segment duration T,
#: the turning point c.
_STATE_DIMENSIONS = ((1, 0), (1, -1), (1, -2), (1, 0), (1, -1), (1, -2), (0, 1), (1, 0))


@functools.lru_cache(maxsize=64)
def variable_dimensions(shape: NlpShape) -> tuple[np.ndarray, np.ndarray]:
    """Powers of length and of time of each NLP variable, in the stage layout; shape (size,) each.

    Controls: the two jerks as shares of the max jerk (dimensionless), then a segment's
    duration (time) and a turning point (length) where the stage carries them.
    """
    dims: list[tuple[int, int]] = list(_STATE_DIMENSIONS)
    for stage in stages(shape):
        dims += [(0, 0), (0, 0)]
        dims += [(0, 1)] if stage.new_segment else []
        dims += [(1, 0)] if stage.new_depth else []
        dims += _STATE_DIMENSIONS
    powers = np.array(dims, dtype=int)
    length, time = powers[:, 0].copy(), powers[:, 1].copy()
    length.flags.writeable = False
    time.flags.writeable = False
    return length, time


@dataclass(frozen=True, slots=True)
class ProblemUnits:
    """The length and time units one problem is solved in.

    Attributes
    ----------
    length : float
        Metres per unit of length, > 0.
    time : float
        Seconds per unit of time, > 0.
    """

    length: float
    time: float

    @classmethod
    def of(cls, bound: float) -> ProblemUnits:
        """The units for a class whose lower bound is ``bound`` seconds (see :data:`TIME_SHARE`).

        Examples
        --------
        >>> ProblemUnits.of(27.5), ProblemUnits.of(1502.6)
        (ProblemUnits(length=1.0, time=1.0), ProblemUnits(length=32.0, time=32.0))
        """
        if not 0.0 < bound < math.inf:  # nothing moves, or no bound: seconds and metres
            return cls(1.0, 1.0)
        time = 2.0 ** max(0, math.floor(math.log2(TIME_SHARE * bound)))
        return cls(time, time)

    @property
    def is_identity(self) -> bool:
        """Whether these are seconds and metres."""
        return self.length == 1.0 and self.time == 1.0

    def scale(self, length_power: np.ndarray, time_power: np.ndarray) -> np.ndarray:
        """The unit of quantities of these dimensions: ``length**l * time**t``, elementwise."""
        return self.length ** np.asarray(length_power, dtype=float) * self.time ** np.asarray(
            time_power, dtype=float
        )

    def variables(self, shape: NlpShape) -> np.ndarray:
        """The unit of each NLP variable of ``shape``, shape (size,): SI value = NLP value * unit."""
        return self.scale(*variable_dimensions(shape))
