"""Who may call the API (app.access): the Host check on every request, the Origin check on
writes, the token on /api/. An ASGI middleware, so a refused request is answered before its
body is read. Also GET /studio, the door that lets a browser into the studio with the token.
"""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import JSONResponse, RedirectResponse, Response

from app.access import COOKIE, Access

__all__ = ["Guard", "router"]

WRITES = {"POST", "PUT", "PATCH", "DELETE"}
STUDIO_COOKIE_DAYS = 30


class Guard:
    def __init__(self, app, access: Access) -> None:
        self.app, self.access = app, access

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        headers = {k.decode("latin-1"): v.decode("latin-1") for k, v in scope["headers"]}
        host = headers.get("host")
        refusal = self.access.host_refusal(host)
        if refusal is not None:
            return await _answer(400, refusal, scope, receive, send)
        if scope["method"] in WRITES:
            refusal = self.access.origin_refusal(headers.get("origin"), host)
            if refusal is not None:
                return await _answer(403, refusal, scope, receive, send)
        if scope["path"].startswith("/api/") and not self.access.bearer_ok(
                headers.get("authorization")):
            return await _answer(401, "this server needs its token: Authorization: Bearer <token> "
                                      "(trackstar serve --token)", scope, receive, send,
                                 {"WWW-Authenticate": "Bearer"})
        await self.app(scope, receive, send)


async def _answer(status: int, detail: str, scope, receive, send, headers=None) -> None:
    await JSONResponse({"detail": detail}, status_code=status, headers=headers)(scope, receive,
                                                                                 send)


router = APIRouter()


@router.get("/studio", include_in_schema=False)
def studio(request: Request, token: str | None = None) -> Response:
    """To the studio on this host name; with --token, `?token=T` once sets the studio's cookie
    (HttpOnly, SameSite=Strict; cookies ignore the port, so the studio's websocket gets it)."""
    settings = request.app.state.settings
    access: Access = settings.access
    name = request.url.hostname or "localhost"
    response = RedirectResponse(f"{request.url.scheme}://{f'[{name}]' if ':' in name else name}"
                                f":{settings.ui_port}/", status_code=303)
    if access.token is None or access.cookie_ok(request.headers.get("cookie")):
        return response
    if token is None or not access.bearer_ok(f"Bearer {token}"):
        return JSONResponse({"detail": "open /studio?token=<token> once (the token of "
                                       "trackstar serve --token)"}, status_code=401)
    response.set_cookie(COOKIE, access.studio_pass, max_age=STUDIO_COOKIE_DAYS * 86400,
                        httponly=True, samesite="strict")
    return response
