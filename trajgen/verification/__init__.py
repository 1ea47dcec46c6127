"""The independent verifier: nothing leaves the library unless it passes.

:func:`verify` checks a schedule in closed form, piece by piece; :func:`certify` turns a passing
schedule into a :class:`VerifiedSchedule`, the only kind that exporters and plots accept.
"""

from trajgen.verification.certify import VerifiedSchedule, certify, require_verified, verify
from trajgen.verification.report import (
    CONTINUITY_TOLERANCE,
    POSITION_TOLERANCE,
    RELATIVE_TOLERANCE,
    REST_TOLERANCE,
    TRACK_END_TOLERANCE,
    VerificationReport,
)

__all__ = [
    "CONTINUITY_TOLERANCE",
    "POSITION_TOLERANCE",
    "RELATIVE_TOLERANCE",
    "REST_TOLERANCE",
    "TRACK_END_TOLERANCE",
    "VerificationReport",
    "VerifiedSchedule",
    "certify",
    "require_verified",
    "verify",
]
