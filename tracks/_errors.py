"""The one error type of the tracks layer."""

from __future__ import annotations


class TrackError(ValueError):
    """Input that cannot become a track: bad file, bad SVG, unknown path id, impossible option.

    A `ValueError`, so callers (and the CLI's `user_errors`) need to know nothing more; the message
    says what is wrong in one line.
    """
