"""``python -m app.studio [--port P]``: the studio alone, without the REST API.

For development and the studio's own tests; prints ``UI: http://HOST:PORT/`` as
``trackstar serve`` does, and runs until interrupted.
"""

from __future__ import annotations

import argparse
import signal
import threading

from app.studio import launch


def main() -> None:
    ap = argparse.ArgumentParser(prog="python -m app.studio")
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int, default=8080)
    ap.add_argument("--api-url", default="http://127.0.0.1:8000/api/v1")
    args = ap.parse_args()
    handle = launch(args.host, args.port, args.api_url)
    print(f"UI: http://{args.host}:{handle.port}/", flush=True)
    done = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: done.set())
    try:
        done.wait()
    except KeyboardInterrupt:
        pass
    handle.stop()


if __name__ == "__main__":
    main()
