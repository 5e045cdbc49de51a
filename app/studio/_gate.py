"""The studio's door: each websocket's handshake is checked against the server's `Access`
(Host, Origin, and with a token the cookie that GET /studio?token=T sets on the API port).

viser 1.1 has no hook before the handshake (its HTTP hook is a closure inside its server
thread), so the check runs in its first connect callback: after the handshake, before the
studio sends or reads anything. A refused connection is closed (1008, with the reason) and
never gets a session. The page itself (viser's static client) is still served to anyone.
"""

from __future__ import annotations

import logging

import viser

from app.access import Access
from app.pool import first_line

__all__ = ["Gate"]

POLICY_VIOLATION = 1008


class Gate:
    """Closes refused websockets; `admitted(client_id)` tells the studio whether to open a
    session (a message a refused client sent before the close may still arrive)."""

    def __init__(self, server: viser.ViserServer, access: Access) -> None:
        self._ws = server._websock_server  # viser's infra server: it holds the raw connections
        self._access = access
        self._admitted: set[int] = set()  # live connections that passed
        self._ws.on_client_connect(self._check)
        self._ws.on_client_disconnect(lambda client: self._admitted.discard(client.client_id))
        logging.getLogger("websockets.server").addFilter(_one_line)

    async def _check(self, client) -> None:
        connection = self._ws._live_connections.get(client.client_id)
        if connection is None:
            return
        reason = self.reason(connection.request.headers)
        if reason is None:
            self._admitted.add(client.client_id)
        else:  # a close reason holds at most 123 bytes
            await connection.close(POLICY_VIOLATION, reason.encode()[:120].decode(errors="ignore"))

    def reason(self, headers) -> str | None:
        """Why a handshake with these (websockets) headers is refused, or None."""
        host = _one(headers, "Host")
        return (self._access.host_refusal(host)
                or self._access.origin_refusal(_one(headers, "Origin"), host)
                or (None if self._access.cookie_ok(_one(headers, "Cookie"))
                    else "sign in first: open /studio?token=<token> on the API's port"))

    def admitted(self, client_id: int) -> bool:
        return client_id in self._admitted


def _one(headers, name: str) -> str | None:
    """The header's value, None if absent; '' if repeated, which every check refuses."""
    values = headers.get_all(name)
    return (values[0] if len(values) == 1 else "") if values else None


def _one_line(record: logging.LogRecord) -> bool:
    """A client that sends what viser cannot read (random bytes, text, msgpack of the wrong
    types) fails viser's connection handler, and websockets closes that socket (1011): log it
    as one line instead of a traceback per message."""
    if record.msg == "connection handler failed" and record.exc_info:
        exc = record.exc_info[1]
        record.msg = "studio: closed a websocket that sent a malformed message (%s)"
        record.args = (f"{type(exc).__name__}: {first_line(exc)[:200]}" if str(exc)
                       else type(exc).__name__,)
        record.exc_info = record.exc_text = None
    return True
