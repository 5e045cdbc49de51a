"""Slow-header (slowloris) clients against a real `trackstar serve`: a connection whose request
head does not arrive within `HEAD_S` is closed; honest clients, slow ones inside the deadline
and kept-alive connections are served."""

from __future__ import annotations

import socket
import time

import httpx
from _server import Server

from app.server.header_deadline import HEAD_S


def _closed_after(conn: socket.socket, started: float, trickle: bool) -> float:
    """Seconds from ``started`` until the server closed ``conn`` (a header byte a second
    meanwhile when ``trickle``); inf if it stays open past twice the deadline."""
    conn.settimeout(1.0)
    while time.monotonic() - started < 2 * HEAD_S:
        try:
            if trickle:
                conn.sendall(b"X")
            if conn.recv(1024) == b"":
                return time.monotonic() - started
        except TimeoutError:
            continue
        except (BrokenPipeError, ConnectionResetError):
            return time.monotonic() - started
    return float("inf")


def test_a_request_head_that_takes_too_long_closes_its_connection(tmp_path):
    srv = Server(tmp_path)
    try:
        started = time.monotonic()
        silent = socket.create_connection(("127.0.0.1", srv.port))
        slow = socket.create_connection(("127.0.0.1", srv.port))
        slow.sendall(b"GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ")
        # Inside the deadline, a head sent in pieces over two seconds is answered.
        patient = socket.create_connection(("127.0.0.1", srv.port))
        for part in (b"GET /health HTTP/1.1\r\n", b"Host: 127.0.0.1\r\n", b"\r\n"):
            patient.sendall(part)
            time.sleep(1.0)
        patient.settimeout(5.0)
        assert patient.recv(1024).startswith(b"HTTP/1.1 200")
        # A kept-alive connection is not cut between requests, and is served again.
        with httpx.Client(base_url=srv.url, timeout=10) as kept:
            assert kept.get("/health").status_code == 200
            time.sleep(2.0)
            assert kept.get("/health").status_code == 200
        took = [_closed_after(slow, started, trickle=True),
                _closed_after(silent, started, trickle=False)]
        assert all(HEAD_S - 0.5 <= s <= HEAD_S + 3.0 for s in took), took
        assert srv.get("/health").json()["status"] == "ok"
    finally:
        srv.stop()
