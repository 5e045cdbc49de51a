"""`trackstar serve`: the REST API (uvicorn) and the browser studio (viser) in one process.

Both ports are checked here, before anything starts: viser would silently move to the next
free port, and a user must learn that the port they asked for is busy. The API socket is bound
here and handed to uvicorn, so port 0 works and the printed port is the real one.
"""

from __future__ import annotations

import ipaddress
import os
import secrets
import signal
import socket
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated
from urllib.parse import quote

import typer

from app.cli._errors import InputError, user_errors

if TYPE_CHECKING:
    from app.access import Access


def _listen(host: str, port: int, what: str) -> socket.socket:
    """A listening socket on (host, port), or exit 2 naming the busy port."""
    try:
        family = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0][0]
    except socket.gaierror as exc:
        raise InputError(f"cannot resolve host {host!r}: {exc.strerror}") from None
    try:
        return socket.create_server((host, port), family=family)
    except OSError as exc:
        reason = os.strerror(exc.errno) if exc.errno else str(exc)
        raise InputError(f"{what} port {port} on {host} is not available: {reason}") from None


def _is_loopback(host: str) -> bool:
    try:
        address = socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)[0][4][0]
        return ipaddress.ip_address(address).is_loopback
    except (OSError, ValueError):
        return False


def _api_url(host: str, port: int, access: Access) -> str:
    """The API's base URL for the studio's own calls; with a token, it rides in the URL, so
    every call sends it (app.access accepts it as a Basic password)."""
    local = {"0.0.0.0": "127.0.0.1", "::": "::1"}.get(host, host)  # the studio calls from here
    name = f"[{local}]" if ":" in local else local
    login = f"studio:{quote(access.token, safe='')}@" if access.token else ""
    return f"http://{login}{name}:{port}/api/v1"


async def _run(app, api: socket.socket, host: str, ui: socket.socket, generated: bool) -> None:
    """Serve until stopped; ``generated``: the token is this start's own, so it is printed."""
    import asyncio  # here, not at the top: every other command would pay its 20 ms

    import uvicorn

    from app.server.header_deadline import HeaderDeadline
    from app.studio import launch

    api_port, ui_port = api.getsockname()[1], ui.getsockname()[1]
    ui.close()  # viser binds it itself; checked free just now
    access = app.state.settings.access
    studio = await asyncio.to_thread(launch, host, ui_port, _api_url(host, api_port, access),
                                     access)
    try:
        if studio.port != ui_port:
            raise InputError(f"studio port {ui_port} on {host} became busy")
        config = uvicorn.Config(app, log_level="warning", timeout_graceful_shutdown=1,
                                http=HeaderDeadline)
        server = uvicorn.Server(config)
        serving = asyncio.create_task(server.serve(sockets=[api]))
        while not server.started and not serving.done():
            await asyncio.sleep(0.02)
        if server.started:
            print(f"API: http://{host}:{api_port}/docs", flush=True)
            print(f"UI: http://{host}:{ui_port}/", flush=True)
            if generated:
                print(f"Token: {access.token} (generated; choose one with TRACKSTAR_TOKEN, or "
                      f"serve without one with --no-token)", flush=True)
            if access.token:
                shown = quote(access.token, safe="") if generated else "<token>"
                print(f"Studio with the token: http://{host}:{api_port}/studio?token={shown}",
                      flush=True)
        await serving
    finally:
        studio.stop()


def serve(
    host: Annotated[str, typer.Option(envvar="TRACKSTAR_HOST",
                                      help="Interface to listen on.")] = "127.0.0.1",
    port: Annotated[int, typer.Option(envvar="TRACKSTAR_PORT", min=0, max=65535,
                                      help="REST API port (0: any free port).")] = 8000,
    ui_port: Annotated[int, typer.Option(envvar="TRACKSTAR_UI_PORT", min=0, max=65535,
                                         help="Studio port (0: any free port).")] = 8080,
    data_dir: Annotated[Path | None, typer.Option(
        envvar="TRACKSTAR_DATA_DIR", file_okay=False,
        help="Where the SQLite database lives [default: the user data directory].")] = None,
    max_upload_mb: Annotated[float, typer.Option(min=0.001, help="Upload limit (MB).")] = 5.0,
    max_plan_s: Annotated[float, typer.Option(min=0.001, help="Longest plan (s).")] = 30.0,
    max_sim_s: Annotated[float, typer.Option(
        min=0.001, help="Longest simulation, in wall time (s).")] = 300.0,
    token: Annotated[str | None, typer.Option(
        envvar="TRACKSTAR_TOKEN", show_default=False,
        help="Require 'Authorization: Bearer TOKEN' on /api/ and a sign-in at "
             "/studio?token=TOKEN for the studio (prefer the environment variable: a command "
             "line is visible to other users).")] = None,
    allowed_hosts: Annotated[list[str] | None, typer.Option(
        envvar="TRACKSTAR_ALLOWED_HOSTS", show_default=False,
        help="More host names the server answers to, comma-separated or repeated ('*': any); "
             "it always answers to localhost, 127.0.0.1, ::1 and --host.")] = None,
    allow_origin: Annotated[list[str] | None, typer.Option(
        envvar="TRACKSTAR_ALLOW_ORIGIN", show_default=False,
        help="A web origin (https://site.org) allowed to change data and open the studio, "
             "besides the server's own; repeatable.")] = None,
    no_token: Annotated[bool, typer.Option(
        "--no-token", envvar="TRACKSTAR_NO_TOKEN",
        help="Listening beyond loopback, serve without a token: whoever reaches the port may "
             "use it. Otherwise a --host other than loopback without --token gets a generated "
             "token, printed with the studio's sign-in URL (as Jupyter does).")] = False,
) -> None:
    """Serve the REST API (/docs) and the browser studio; Ctrl-C stops both."""
    import platformdirs

    from app.access import Access
    from app.server import ServerSettings, create_app

    with user_errors():
        if token is not None and (not token.isprintable() or token.strip() != token or not token):
            raise InputError("--token must be printable, without spaces at its ends")
        if token is not None and no_token:
            raise InputError("choose one of --token and --no-token")
        generated = token is None and not no_token and not _is_loopback(host)
        if generated:  # served beyond this machine: nobody uses it without the token
            token = secrets.token_urlsafe(24)
        try:
            access = Access.build(host, allowed_hosts or [], allow_origin or [], token)
        except ValueError as exc:
            raise InputError(str(exc)) from None
        api = _listen(host, port, "API")
        try:
            ui = _listen(host, ui_port, "studio")
        except InputError:
            api.close()
            raise
        if ui_port == 0 and ui.getsockname()[1] == api.getsockname()[1]:
            raise InputError("the studio and the API need different ports")
        data = data_dir or Path(platformdirs.user_data_dir("trackstar"))
        settings = ServerSettings(data_dir=data, max_upload_mb=max_upload_mb,
                                  max_plan_s=max_plan_s, max_sim_s=max_sim_s,
                                  ui_port=ui.getsockname()[1],
                                  access=access)
        if not _is_loopback(host) and access.token is None:
            print(f"warning: listening on {host} with --no-token: whoever reaches it may use "
                  "it (docs/server.md: a shared server)", file=sys.stderr, flush=True)
        from app.kernels import warm_in_background

        warm_in_background()  # answer at once; a first start after an install compiles them
        # uvicorn re-raises the stop signal once it has shut down; we have already stopped.
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, lambda *_: None)
        import asyncio

        asyncio.run(_run(create_app(settings), api, host, ui, generated))


def register(cli: typer.Typer) -> None:
    cli.command("serve")(serve)
