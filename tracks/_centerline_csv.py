"""Centreline CSVs of the racing community (TUM racetrack database, F1TENTH racetracks).

``# x_m,y_m,w_tr_right_m,w_tr_left_m`` then one row per point: centreline x, y in metres and
the track's width to the right and to the left of the driving direction. A loop by default
(its first point not repeated; a repeated last point is dropped). The centreline is the C2
spline through the points (`spline_beziers`), so the rest of `tracks` sees Béziers as from
any SVG; the side widths go with it, linear in s between the points.
"""

from __future__ import annotations

import math
import re

import numpy as np

from tracks._errors import TrackError
from tracks._spline import spline_beziers
from tracks._track import Track

COLUMNS = ("x_m", "y_m", "w_tr_right_m", "w_tr_left_m")
_SEPARATOR = re.compile(r"\s*[,;]\s*")
# Rows of one file: a 10 km track at 1 m spacing. Each row becomes a Bézier that is measured,
# so this bounds a load to about two seconds; the TUM and F1TENTH tracks have 1 000 to 5 000.
MAX_ROWS = 10_000


def _rows(text: str, name: str) -> tuple[np.ndarray, list[int]]:
    """The numbers (n, 4) and the line number of each row; `#` lines and blank lines skipped."""
    rows, lines = [], []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        fields = _SEPARATOR.split(line)
        where = f"{name} line {number}"
        if len(fields) != 4:
            raise TrackError(f"{where}: expected 4 numbers ({', '.join(COLUMNS)}), "
                             f"got {len(fields)} fields")
        try:
            values = [float(f) for f in fields]
        except ValueError:
            raise TrackError(f"{where}: not a number in {line[:60]!r}") from None
        if not all(math.isfinite(v) for v in values):
            raise TrackError(f"{where}: NaN or infinite value")
        if min(values[2:]) < 0:
            raise TrackError(f"{where}: negative width")
        rows.append(values)
        lines.append(number)
        if len(rows) > MAX_ROWS:
            raise TrackError(f"{where}: more than {MAX_ROWS} rows; resample the centreline "
                             f"more coarsely (every metre is plenty for planning)")
    return np.array(rows).reshape(-1, 4), lines


def read_centerline_csv(data: bytes, *, closed: bool = True, name: str = "centerline") -> Track:
    """The track of a centreline CSV (see the module's docstring); errors name the line."""
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise TrackError(f"{name}: not a text file (UTF-8 expected)") from None
    rows, lines = _rows(text, name)
    if not len(rows):
        raise TrackError(f"{name}: no points (an empty file?); expected rows of "
                         f"{', '.join(COLUMNS)}")
    if closed and len(rows) > 1 and np.array_equal(rows[0, :2], rows[-1, :2]):
        rows, lines = rows[:-1], lines[:-1]
    if len(rows) < 4:
        raise TrackError(f"{name}: a centreline needs at least 4 points, got {len(rows)}")
    same = np.flatnonzero((np.diff(rows[:, :2], axis=0) == 0).all(axis=1))
    if len(same):
        raise TrackError(f"{name} line {lines[same[0] + 1]}: repeats the point of line "
                         f"{lines[same[0]]}")
    total = rows[:, 2] + rows[:, 3]
    if not total.min() > 0:
        raise TrackError(f"{name} line {lines[int(total.argmin())]}: the track has no width")
    widths = np.vstack([rows[:, 2:], rows[:1, 2:]]) if closed else rows[:, 2:]
    return Track(name=name, closed=closed, width_m=float(total.min()),
                 segments=tuple(spline_beziers(rows[:, :2], closed)), side_widths=widths)


def centerline_csv(track: Track, spacing: float = 0.05) -> str:
    """The track as a centreline CSV: a row every ``spacing`` m with its side widths (a loop's
    closing point is not repeated, as the format wants)."""
    prof = track.sample(spacing)
    end = len(prof.s) - 1 if track.closed else len(prof.s)
    right, left = track.widths_at(prof.s[:end])
    rows = np.column_stack([prof.x[:end], prof.y[:end], right, left])
    lines = [f"# {','.join(COLUMNS)}"] + [",".join(f"{v:.7f}" for v in row) for row in rows]
    return "\n".join(lines) + "\n"
