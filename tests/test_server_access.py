"""Who may call (issue 19), against a real `trackstar serve --token`: the token on /api/, the
Origin check on writes, the Host allow-list, the studio's sign-in and its websocket door."""

from __future__ import annotations

import asyncio

import httpx
import pytest
import viser
from _server import Server
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed

from app.access import Access

TOKEN = "class-of-2025"
COURSE = "https://course.example"
PLAN = {"scenario_id": "slalom", "time": 0.05, "seed": 1}


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    srv = Server(tmp_path_factory.mktemp("data"), "--allow-origin", COURSE,
                 "--allowed-hosts", "lab.example,10.0.0.5", "--allowed-hosts", "lab2.example",
                 env={"TRACKSTAR_TOKEN": TOKEN})
    srv.client.headers["Authorization"] = f"Bearer {TOKEN}"
    yield srv
    srv.stop()


def test_the_api_needs_the_token_and_health_and_docs_do_not(server):
    bare = httpx.Client(base_url=server.url, timeout=30)
    refused = bare.get("/api/v1/tracks")
    assert refused.status_code == 401 and "Bearer" in refused.json()["detail"]
    assert refused.headers["www-authenticate"] == "Bearer"
    assert bare.get("/api/v1/tracks", headers={"Authorization": "Bearer wrong"}).status_code == 401
    assert bare.get("/api/v1/tracks", auth=("any", TOKEN)).status_code == 200  # curl -u :T
    assert bare.get("/health").status_code == 200
    assert "token" in bare.get("/openapi.json").json()["components"]["securitySchemes"]
    assert server.client.get("/tracks").status_code == 200


@pytest.mark.parametrize("origin, status", [
    (None, 200),                        # curl, scripts
    ("http://127.0.0.1:{port}", 200),   # the server's own pages (/docs)
    (COURSE, 200),                      # --allow-origin
    ("http://evil.example", 403),
    ("http://127.0.0.1:1", 403),        # another port is another origin
    ("null", 403),                      # a sandboxed frame
])
def test_writes_from_another_origin_are_refused(server, origin, status):
    headers = {} if origin is None else {"Origin": origin.format(port=server.port)}
    r = server.client.post("/plan", json=PLAN, headers=headers)
    assert r.status_code == status, r.text
    if status == 403:
        assert "--allow-origin" in r.json()["detail"]
    reads = server.client.get("/scenarios", headers=headers)
    assert reads.status_code == 200  # a read from anywhere is no write


def test_only_allowed_host_names_are_served(server):
    for name in ("lab.example", "lab2.example", "10.0.0.5", "localhost"):
        assert server.get("/health", headers={"Host": f"{name}:{server.port}"}).status_code == 200
    r = server.get("/health", headers={"Host": f"rebound.evil.example:{server.port}"})
    assert r.status_code == 400 and "--allowed-hosts" in r.json()["detail"]


def test_default_hosts_are_loopback_and_the_bound_host():
    assert Access.build("10.1.2.3", [], [], None).hosts == {"localhost", "127.0.0.1", "::1",
                                                            "10.1.2.3"}
    assert Access.build("0.0.0.0", ["a.example, B.example"], [], None).hosts == {
        "localhost", "127.0.0.1", "::1", "a.example", "b.example"}
    wildcard = Access.build("0.0.0.0", [], [], None)
    assert wildcard.host_refusal("[::1]:8000") is None
    assert wildcard.host_refusal("0.0.0.0:8000") is not None
    assert Access.build("0.0.0.0", ["*"], [], None).host_refusal("any.example") is None
    with pytest.raises(ValueError, match="not an origin"):
        Access.build("localhost", [], ["course.example"], None)


def test_studio_sign_in_sets_a_cookie_for_the_studio_port(server):
    bare = httpx.Client(base_url=server.url, timeout=30)
    assert bare.get("/studio").status_code == 401
    assert bare.get("/studio", params={"token": "wrong"}).status_code == 401
    r = bare.get("/studio", params={"token": TOKEN})
    assert r.status_code == 303
    assert r.headers["location"] == f"http://127.0.0.1:{server.ui_port}/"
    cookie = r.headers["set-cookie"]
    assert "HttpOnly" in cookie and "SameSite=strict" in cookie and TOKEN not in cookie
    assert bare.get("/studio").status_code == 303  # the cookie is enough from now on
    odd = httpx.get(f"{server.url}/studio", headers={"Cookie": 'trackstar_studio="\u00e9"'.encode()})
    assert odd.status_code == 401  # a non-ASCII cookie is a wrong one, not a 500


def _studio(server, **headers) -> str:
    """'open' if the studio's websocket sends a first message with these handshake headers,
    else its close code and reason."""
    async def probe() -> str:
        async with connect(f"ws://127.0.0.1:{server.ui_port}/", additional_headers=headers,
                           subprotocols=[f"viser-v{viser.__version__}"]) as ws:
            try:
                await asyncio.wait_for(ws.recv(), 10)
                return "open"
            except ConnectionClosed as closed:
                return f"{closed.rcvd.code} {closed.rcvd.reason}"
    return asyncio.run(probe())


def test_the_studio_websocket_needs_the_cookie_and_its_own_origin(server):
    r = httpx.get(f"{server.url}/studio", params={"token": TOKEN})
    cookie = r.headers["set-cookie"].split(";")[0]
    own = f"http://127.0.0.1:{server.ui_port}"
    assert _studio(server, Origin=own, Cookie=cookie) == "open"
    assert _studio(server, Origin=own).startswith("1008 sign in first")
    assert _studio(server, Origin="http://evil.example", Cookie=cookie).startswith(
        "1008 origin 'http://evil.example'")
    assert _studio(server, Origin=COURSE, Cookie=cookie) == "open"
    assert _studio(server, Origin=own, Cookie='trackstar_studio="\u00e9"').startswith(
        "1008 sign in first")
