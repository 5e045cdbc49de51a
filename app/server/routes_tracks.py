"""/tracks: the bundled library and uploaded tracks (Inkscape SVG or centreline CSV), their
geometry, profiles, centreline CSVs and racelines."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import Annotated

from fastapi import APIRouter, Form, HTTPException, Request, Response, UploadFile
from fastapi.concurrency import run_in_threadpool

import tracks
from app.raceline import A_LAT_MAX, A_LONG_MAX, raceline_limits
from app.server.models import SvgPaths, TrackGeometry, TrackProfile, TrackSummary

router = APIRouter(tags=["tracks"])

MAX_LENGTH_M = 10_000.0  # longer is a wrong unit, and its samples would not fit a response
MAX_POINTS = 200_000  # per sampled profile
GEOMETRY_POINTS = 20_000  # the coarsest spacing of GET /tracks/{id} keeps it below this


@lru_cache(maxsize=16)
def _library_track(name: str) -> tracks.Track:
    return tracks.load_library_track(name)


@lru_cache(maxsize=16)
def _upload_track(track_id: str, data: bytes, path: str | None, unit: str | None,
                  closed: bool) -> tracks.Track:
    return tracks.load_track(data, path_id=path, unit=unit, closed=closed)


def _stored(request: Request, track_id: str) -> dict:
    row = request.app.state.store.track(track_id)
    if row is None:
        raise HTTPException(404, f"no track {track_id!r} (GET /api/v1/tracks lists them)")
    return row


def _track(request: Request, track_id: str) -> tracks.Track:
    if track_id in tracks.library_names():
        return _library_track(track_id)
    row = _stored(request, track_id)
    return _upload_track(row["id"], row["svg"], row["path"], row["unit"], bool(row["closed"]))


def _summary(track_id: str, name: str, source: str, track: tracks.Track) -> TrackSummary:
    return TrackSummary(id=track_id, name=name, source=source, closed=track.closed,
                        length_m=track.length_m, width_m=track.width_m)


@router.get("/tracks", response_model=list[TrackSummary])
def list_tracks(request: Request) -> list[TrackSummary]:
    """Every track: the bundled library first, then uploads in upload order."""
    library = [_summary(n, n, "library", _library_track(n)) for n in tracks.library_names()]
    uploads = [TrackSummary(source="upload", **row) for row in request.app.state.store.tracks()]
    return library + uploads


def _read_upload(data: bytes, filename: str, path: str | None, unit: str | None,
                 closed: bool | None) -> tracks.Track:
    kind = "SVG" if tracks.is_svg(data, filename) else "CSV"
    try:
        track = tracks.load_track(data, path_id=path, unit=unit, closed=closed,
                                  filename=filename)
    except ValueError as exc:  # TrackError, and units it does not know
        raise HTTPException(400, f"cannot use this {kind}: {exc}") from None
    if track.length_m > MAX_LENGTH_M:
        raise HTTPException(400, f"the track is {track.length_m:.0f} m long (limit "
                                 f"{MAX_LENGTH_M:.0f} m): is 'unit' right?")
    return track


@router.post("/tracks", response_model=TrackSummary, status_code=201)
async def upload_track(
    request: Request,
    file: UploadFile,
    path: Annotated[str | None, Form(description="element id or inkscape:label "
                                                 "(default: the longest path)")] = None,
    unit: Annotated[str | None, Form(description="what one user unit measures: "
                                                 "m, cm, mm, in, pt, pc, px")] = None,
    closed: Annotated[bool | None, Form(description="a centreline CSV: a loop (default) or "
                                                    "a road (false)")] = None,
) -> TrackSummary:
    """Upload an Inkscape SVG (its track is the chosen path; every path stays listed in
    GET /tracks/{id}/paths) or a centreline CSV (x_m, y_m, w_tr_right_m, w_tr_left_m rows)."""
    cap = request.app.state.settings.max_upload_bytes
    data = await file.read(cap + 1)
    if len(data) > cap:
        raise HTTPException(413, f"the file is above the upload limit of {cap} bytes")
    track = await run_in_threadpool(_read_upload, data, file.filename or "", path or None,
                                    unit or None, closed)
    name = path or Path(file.filename or "").stem or track.name
    store = request.app.state.store
    track_id = store.add_track(name, data, path or None, unit or None, track.closed,
                               track.length_m, track.width_m)
    return _summary(track_id, name, "upload", track)


@router.get("/tracks/{track_id}", response_model=TrackGeometry)
def track_geometry(request: Request, track_id: str) -> TrackGeometry:
    """Centreline and both edges in metres, world frame, every 2 cm (coarser on long tracks)."""
    track = _track(request, track_id)
    spacing = max(0.02, track.length_m / GEOMETRY_POINTS)
    profile = track.sample(spacing)
    left, right = track.boundaries(spacing)
    name = track_id if track_id in tracks.library_names() else _stored(request, track_id)["name"]
    return TrackGeometry(
        id=track_id, name=name, closed=track.closed, length_m=track.length_m,
        width_m=track.width_m, centerline=list(zip(profile.x.tolist(), profile.y.tolist())),
        left=left.tolist(), right=right.tolist())


@router.get("/tracks/{track_id}/paths", response_model=SvgPaths)
def track_paths(request: Request, track_id: str) -> dict:
    """Every path-like element of the track's file, like `trackstar track inspect --json`."""
    if track_id in tracks.library_names():
        return tracks.inspect_svg(tracks.library_path(track_id))
    row = _stored(request, track_id)
    return tracks.inspect_track(row["svg"], unit=row["unit"], closed=bool(row["closed"]))


@router.get("/tracks/{track_id}/profile", response_model=TrackProfile)
def track_profile(request: Request, track_id: str, spacing: float = 0.02,
                  wheelbase: float = 0.44, max_steer_deg: float = 26.0) -> dict:
    """Target points with heading, curvature and steering angle: `track sample --json`."""
    try:
        tracks.check_sampling(spacing, wheelbase, max_steer_deg)
    except ValueError as exc:
        raise HTTPException(422, str(exc)) from None
    track = _track(request, track_id)
    _checked_spacing(track, spacing)
    return track.sample(spacing, wheelbase, max_steer_deg).to_dict()


@router.get("/tracks/{track_id}/svg", response_class=Response,
            responses={200: {"content": {"image/svg+xml": {}}}})
def track_svg(request: Request, track_id: str) -> Response:
    """The track as an Inkscape-compatible SVG (mm document, stroke width = track width)."""
    return Response(_track(request, track_id).to_svg(), media_type="image/svg+xml")


def _checked_spacing(track: tracks.Track, spacing: float) -> None:
    """422 unless the spacing is positive and gives at most MAX_POINTS rows."""
    try:
        tracks.check_sampling(spacing)
    except ValueError as exc:
        raise HTTPException(422, str(exc)) from None
    if track.length_m / spacing > MAX_POINTS:
        raise HTTPException(422, f"spacing {spacing} m gives more than {MAX_POINTS} points on "
                                 f"this {track.length_m:.1f} m track")


@router.get("/tracks/{track_id}/centerline.csv", response_class=Response,
            responses={200: {"content": {"text/csv": {}}}})
def track_centerline(request: Request, track_id: str, spacing: float = 0.05) -> Response:
    """The centreline every ``spacing`` m with its side widths: `track export --format
    tum-centerline`."""
    track = _track(request, track_id)
    _checked_spacing(track, spacing)
    return Response(tracks.centerline_csv(track, spacing), media_type="text/csv")


@router.get("/tracks/{track_id}/raceline.csv", response_class=Response,
            responses={200: {"content": {"text/csv": {}}}})
def track_raceline(request: Request, track_id: str, spacing: float = 0.05,
                   v_max: float | None = None, a_lat_max: float = A_LAT_MAX,
                   a_long_max: float = A_LONG_MAX) -> Response:
    """The centreline in the TUM raceline layout with the fastest speed profile within the
    limits (v_max default: the default vehicle's): `trackstar track raceline`."""
    track = _track(request, track_id)
    _checked_spacing(track, spacing)
    try:
        limits = raceline_limits(v_max, a_lat_max, a_long_max)
    except ValueError as exc:
        raise HTTPException(422, str(exc)) from None
    rows = tracks.raceline_rows(track.sample(spacing), limits)
    return Response(tracks.raceline_csv(rows), media_type="text/csv")


@router.delete("/tracks/{track_id}", status_code=204)
def delete_track(request: Request, track_id: str) -> Response:
    """Delete an uploaded track (library tracks are read-only: 403)."""
    if track_id in tracks.library_names():
        raise HTTPException(403, f"{track_id!r} is a library track; only uploads can be deleted")
    if not request.app.state.store.delete_track(track_id):
        raise HTTPException(404, f"no track {track_id!r}")
    return Response(status_code=204)
