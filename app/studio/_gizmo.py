"""Ground-plane gizmos (viser's transform controls): what the editor and the track drawing drag.

Gizmo callbacks are ``async`` so viser runs them in order on its event loop. A drag only moves
what the caller draws (one position update); the release commits on a thread, because what it
commits (compiling a scenario, restarting the planner) takes longer than a frame.
"""

from __future__ import annotations

import threading

from app.studio._scene import Z, wxyz_yaw, yaw_wxyz

__all__ = ["GIZMO_PX", "gizmo"]

GIZMO_PX = 70  # gizmos keep their size on screen, whatever the track's scale
TURN_ONLY_Z = ((0.0, 0.0), (0.0, 0.0), (-1000.0, 1000.0))


def gizmo(scene, name: str, pose, on_move, on_commit=None, rotate: bool = True,
          px: int = GIZMO_PX, visible: bool = True):
    """A gizmo at pose (x, y, yaw): translate in x/y, turn about z only. ``on_move(x, y, yaw)``
    runs on every change, ``on_commit(x, y, yaw)`` (if given) at release."""
    h = scene.add_transform_controls(
        name, scale=px, fixed=True, active_axes=(True, True, False), disable_rotations=not rotate,
        rotation_limits=TURN_ONLY_Z, depth_test=False, position=(pose[0], pose[1], Z["pose"]),
        wxyz=yaw_wxyz(pose[2]), visible=visible)

    @h.on_update
    async def _(ev) -> None:
        x, y, _ = ev.target.position
        yaw = wxyz_yaw(ev.target.wxyz)
        on_move(x, y, yaw)
        if ev.phase == "end" and on_commit is not None:
            threading.Thread(target=on_commit, args=(x, y, yaw), daemon=True).start()

    return h
