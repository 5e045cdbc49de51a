"""A studio tab without a browser: a real studio (`launch`) and a websocket client speaking
viser's protocol, which sends the camera message a canvas sends once it is up and then reads
(and drops) what the studio sends, so the session runs as under a browser."""

from __future__ import annotations

import asyncio
import threading
import time
from contextlib import contextmanager

import msgspec
import viser
from websockets.asyncio.client import connect

from app.studio import launch

# What viser's client sends once its canvas is up: the studio opens a session on it.
CAMERA = msgspec.msgpack.encode({
    "type": "ViewerCameraMessage", "wxyz": (1.0, 0.0, 0.0, 0.0), "position": (0.0, 0.0, 5.0),
    "fov": 1.0, "near": 0.01, "far": 100.0, "image_height": 480, "image_width": 640,
    "look_at": (0.0, 0.0, 0.0), "up_direction": (0.0, 0.0, 1.0)})


@contextmanager
def open_tab():
    """The session of one connected tab (the thesis track); the studio stops on exit."""
    studio = launch("127.0.0.1", 0, "http://127.0.0.1:9/api/v1")  # no API: none is called
    closed = threading.Event()

    async def tab() -> None:
        async with connect(f"ws://127.0.0.1:{studio.port}/",
                           subprotocols=[f"viser-v{viser.__version__}"]) as ws:
            await ws.send(CAMERA)
            while not closed.is_set():
                try:
                    await asyncio.wait_for(ws.recv(), 0.1)
                except TimeoutError:
                    pass

    client = threading.Thread(target=asyncio.run, args=(tab(),), daemon=True)
    client.start()
    try:
        assert wait(lambda: studio.sessions)
        yield next(iter(studio.sessions.values()))
    finally:
        closed.set()
        client.join(timeout=5)
        studio.stop()


def wait(condition, timeout: float = 60.0) -> bool:
    """Whether ``condition()`` came true within ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.02)
    return bool(condition())
