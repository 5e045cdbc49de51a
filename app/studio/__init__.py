"""The browser studio (viser): one session per browser tab, served on its own port.

`launch` is the seam between the server and the studio: `trackstar serve` calls it once both
ports are known free, and calls `stop()` on the returned handle at shutdown.
"""

from __future__ import annotations

from dataclasses import dataclass

import viser

__all__ = ["StudioHandle", "launch"]


@dataclass
class StudioHandle:
    """A running studio: its viser server and the port it really listens on."""

    server: viser.ViserServer
    port: int

    def stop(self) -> None:
        self.server.stop()


def launch(host: str, port: int, api_url: str) -> StudioHandle:
    """Start the studio's viser server on (host, port); ``api_url`` is the REST API's base URL
    (for saving and loading scenarios through the server's store)."""
    server = viser.ViserServer(host=host, port=port, verbose=False)
    server.gui.add_markdown("**Trackstar studio** — tracks, obstacles and RRT* live.")
    return StudioHandle(server=server, port=server.get_port())
