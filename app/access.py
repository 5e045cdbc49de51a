"""Who may call the server: the Host names it answers to, the web origins it takes changes
from, and its token. One policy for both ports, so the API (app.server.guard) and the studio's
websocket (app.studio) refuse the same callers with the same words.

A browser sends `Origin` with every cross-site write and with every websocket handshake, so a
foreign page is refused by that header; a page reached through a rebound DNS name carries that
name in `Host`, which the allow-list refuses.
"""

from __future__ import annotations

import base64
import hashlib
import hmac
from dataclasses import dataclass
from http.cookies import CookieError, SimpleCookie
from urllib.parse import urlsplit

__all__ = ["COOKIE", "LOOPBACK", "Access", "host_name"]

LOOPBACK = ("localhost", "127.0.0.1", "::1")
COOKIE = "trackstar_studio"  # the studio's pass, set by GET /studio?token=…


def host_name(netloc: str) -> str:
    """'Example.org:8000' → 'example.org', '[::1]:8080' → '::1'."""
    netloc = netloc.strip().lower()
    if netloc.startswith("["):
        return netloc[1:].partition("]")[0]
    return netloc.rpartition(":")[0] if netloc.count(":") == 1 else netloc


def _netloc(origin: str) -> str | None:
    """'http://a.org:80' → 'a.org', 'https://a.org:8443' → 'a.org:8443'; None if no URL."""
    try:
        parts = urlsplit(origin.strip().lower())
        port = parts.port
    except ValueError:
        return None
    if not parts.scheme or not parts.hostname:
        return None
    default = {"http": 80, "https": 443}.get(parts.scheme)
    name = f"[{parts.hostname}]" if ":" in parts.hostname else parts.hostname
    return name if port in (None, default) else f"{name}:{port}"


@dataclass(frozen=True)
class Access:
    """The server's callers: allowed Host names ('*': any), extra allowed origins (URLs) and
    the token (None: none required)."""

    hosts: frozenset[str] = frozenset(LOOPBACK)
    origins: frozenset[str] = frozenset()
    token: str | None = None

    @classmethod
    def build(cls, bound_host: str, hosts: list[str], origins: list[str],
              token: str | None) -> Access:
        """The policy of `trackstar serve`: the loopback names (the studio's own calls and a
        health check use them; a rebound DNS name cannot), the bound host unless it is a
        wildcard address, and the --allowed-hosts."""
        names = {host_name(h) for item in hosts for h in item.split(",") if h.strip()}
        names |= set(LOOPBACK) | ({host_name(bound_host)} - {"0.0.0.0", "::", ""})
        netlocs = {origin: _netloc(origin) for origin in origins}
        bad = [origin for origin, netloc in netlocs.items() if netloc is None]
        if bad:
            raise ValueError(f"--allow-origin {bad[0]!r} is not an origin like https://site.org")
        return cls(hosts=frozenset(names), origins=frozenset(netlocs.values()), token=token)

    def host_refusal(self, host: str | None) -> str | None:
        """Why a request with this Host header is refused, or None."""
        if "*" in self.hosts or (host and host_name(host) in self.hosts):
            return None
        return (f"host {host!r} is not served here (allowed: {', '.join(sorted(self.hosts))}); "
                "see trackstar serve --allowed-hosts")

    def origin_refusal(self, origin: str | None, host: str | None) -> str | None:
        """Why a browser call from this Origin is refused, or None. No Origin (curl, scripts)
        passes; so does the server's own origin (its netloc is the Host) and --allow-origin."""
        if origin is None:
            return None
        netloc = _netloc(origin)
        if netloc is not None and (netloc in self.origins or netloc == _netloc(f"http://{host}")
                                   or netloc == _netloc(f"https://{host}")):
            return None
        return f"origin {origin!r} may not call this server; see trackstar serve --allow-origin"

    def bearer_ok(self, authorization: str | None) -> bool:
        """`Authorization: Bearer T`, or Basic with T as the password (the studio's own calls
        carry it in the API URL, so every httpx call of the studio sends it)."""
        if self.token is None:
            return True
        scheme, _, value = (authorization or "").partition(" ")
        if scheme.lower() == "basic":
            try:
                value = base64.b64decode(value, validate=True).decode().partition(":")[2]
            except ValueError:
                return False
        elif scheme.lower() != "bearer":
            return False
        return hmac.compare_digest(value.strip().encode(errors="replace"), self.token.encode())

    @property
    def studio_pass(self) -> str:
        """The studio cookie's value: derived from the token, so the cookie is not the token."""
        assert self.token is not None
        return hmac.new(self.token.encode(), b"trackstar studio", hashlib.sha256).hexdigest()

    def cookie_ok(self, cookie_header: str | None) -> bool:
        """The studio's check: the cookie GET /studio?token=T set (always, without a token)."""
        if self.token is None:
            return True
        try:
            jar = SimpleCookie(cookie_header or "")
        except CookieError:
            return False
        morsel = jar.get(COOKIE)
        # As bytes: compare_digest refuses non-ASCII str (a 500 before), and a websocket's
        # headers may hold undecodable bytes as surrogates.
        return morsel is not None and hmac.compare_digest(
            morsel.value.encode(errors="replace"), self.studio_pass.encode())
