"""The browser studio (viser): one session per browser tab, served on its own port.

`launch` is the seam between the server and the studio: `trackstar serve` calls it once both
ports are known free, and calls `stop()` on the returned handle at shutdown.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

import viser

from app import kernels
from app.access import Access

__all__ = ["StudioHandle", "launch"]

PREPARING = ("**Preparing the planner** (the first start after an install compiles it: about a "
             "minute) …")


@dataclass
class StudioHandle:
    """A running studio: its viser server and the port it really listens on."""

    server: viser.ViserServer
    port: int
    sessions: dict = field(default_factory=dict)

    def stop(self) -> None:
        for session in list(self.sessions.values()):
            session.close()
        self.server.stop()


def launch(host: str, port: int, api_url: str, access: Access | None = None) -> StudioHandle:
    """Start the studio's viser server on (host, port); ``api_url`` is the REST API's base URL
    (for saving and loading scenarios through the server's store); ``access`` says which
    browsers may connect (default: loopback names and ``host``, no token)."""
    from app.studio._gate import Gate
    from app.studio._session import Session

    server = viser.ViserServer(host=host, port=port, verbose=False)
    server.gui.configure_theme(control_width="large", show_share_button=False)
    server.scene.world_axes.visible = False
    server.scene.configure_default_lights(cast_shadow=False)
    handle = StudioHandle(server=server, port=server.get_port())
    gate = Gate(server, access or Access.build(host, [], [], None))
    lock = threading.Lock()

    def _open(client: viser.ClientHandle) -> None:
        """Build the tab's session and keep it until `_disconnect`; if the tab closed while it
        was built, `_disconnect` found nothing to close, so the session closes itself here
        (else its threads would run, and hold it, forever). viser drops a client from
        `get_clients` before it calls `_disconnect`, so exactly one of the two closes it."""
        if not kernels.ready():  # the server has just started: it loads them in the background
            note = client.gui.add_markdown(PREPARING)
            kernels.wait()
            note.remove()
        session = Session(client, api_url)
        with lock:
            if client.client_id in server.get_clients():
                handle.sessions[client.client_id] = session
                return
        session.close()

    @server.on_client_connect
    def _connect(client: viser.ClientHandle) -> None:
        if not gate.admitted(client.client_id):
            return
        # Off the event loop: building a session (track, meshes, a planner) takes a moment and
        # other tabs must not wait for it.
        threading.Thread(target=_open, args=(client,), daemon=True, name="studio-open").start()

    @server.on_client_disconnect
    def _disconnect(client: viser.ClientHandle) -> None:
        with lock:
            session = handle.sessions.pop(client.client_id, None)
        if session is not None:
            session.close()

    return handle
