"""Studio sessions come and go with their tabs: a real studio (`launch`) and a raw websocket
client speaking viser's protocol, no browser. A closed tab leaves no session, thread or handle
behind, however early it closed (issue 19: the server's memory grew with every closed tab)."""

from __future__ import annotations

import asyncio
import gc
import threading
import time

import pytest
import viser
from websockets.asyncio.client import connect

from app.studio import launch
from app.studio._session import Session
from tests._studio_tab import CAMERA


@pytest.fixture
def studio():
    handle = launch("127.0.0.1", 0, "http://127.0.0.1:9/api/v1")  # no API: none is called
    yield handle
    handle.stop()


def _threads(*names: str) -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name in names]


def _wait(condition, timeout: float = 20.0) -> bool:
    deadline = time.monotonic() + timeout
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.02)
    return condition()


def test_a_tab_closed_while_its_session_is_built_leaves_nothing_behind(studio):
    async def tab() -> None:
        async with connect(f"ws://127.0.0.1:{studio.port}/",
                           subprotocols=[f"viser-v{viser.__version__}"]) as ws:
            await ws.send(CAMERA)
            # Closed as soon as its session is being built, long before it is done.
            await asyncio.to_thread(_wait, lambda: _threads("studio-open"))

    asyncio.run(tab())
    assert _wait(lambda: not _threads("studio-open", "studio-ui", "planner"))
    assert studio.sessions == {}
    gc.collect()
    assert not [o for o in gc.get_objects() if isinstance(o, Session)]
