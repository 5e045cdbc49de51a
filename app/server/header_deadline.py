"""A deadline on every request's head: uvicorn reads a request line and headers for as long as
they take, so a client that connects and sends nothing, or trickles a byte every few seconds
(slowloris), holds a socket and a file descriptor for ever. `HeaderDeadline` is uvicorn's h11
protocol that closes such a connection once its head has taken `HEAD_S`."""

from __future__ import annotations

import h11
from uvicorn.protocols.http.h11_impl import H11Protocol

__all__ = ["HEAD_S", "HeaderDeadline"]

HEAD_S = 10.0  # s from a connection, or from a kept-alive request's first byte, to its last header


class HeaderDeadline(H11Protocol):
    """uvicorn's `H11Protocol` with a deadline on each request's head (not on its body, which
    the routes read with their own size limits, nor on the response)."""

    _head_timer = None

    def connection_made(self, transport) -> None:
        super().connection_made(transport)
        self._arm()

    def data_received(self, data: bytes) -> None:
        if self._head_timer is None and self.conn.their_state is h11.IDLE:
            self._arm()  # a kept-alive connection's next request has begun
        super().data_received(data)

    def handle_events(self) -> None:
        super().handle_events()
        if self.conn.their_state is not h11.IDLE:
            self._disarm()  # the head is in

    def connection_lost(self, exc) -> None:
        self._disarm()
        super().connection_lost(exc)

    def _arm(self) -> None:
        self._head_timer = self.loop.call_later(HEAD_S, self._late)

    def _disarm(self) -> None:
        if self._head_timer is not None:
            self._head_timer.cancel()
            self._head_timer = None

    def _late(self) -> None:
        self._head_timer = None
        if self.conn.their_state is h11.IDLE and not self.transport.is_closing():
            self.transport.close()
