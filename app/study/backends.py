"""Where a study's runs execute: this machine's process pool, or a Ray cluster.

Both take a task (a function and its arguments), hand back a handle, and say which handles are
done; the driver alone stores results, so the database, CSV, report and resume behave the same
on either. Scenario data travel with the tasks: a Ray node needs no shared file system.
The pool's modules load with a pool: every command line names the backends.
"""

from __future__ import annotations

import logging
import os
import socket
import tempfile
import threading
import time
from contextlib import contextmanager

__all__ = ["BACKENDS", "LocalBackend", "RayBackend", "open_backend"]


class LocalBackend:
    """A process pool of ``workers`` that keep the planner's kernels warm across runs."""

    @staticmethod
    def check() -> None:
        """This machine can always run its own pool."""

    def __init__(self, workers: int) -> None:
        from app.pool import start_pool

        self.workers = workers
        self._pool = start_pool(workers)

    def submit(self, fn, *args):
        return self._pool.submit(fn, *args)

    def finished(self, handles) -> list:
        from concurrent.futures import FIRST_COMPLETED, wait

        return list(wait(handles, return_when=FIRST_COMPLETED)[0])

    def result(self, handle):
        return handle.result()

    def close(self) -> None:
        from app.pool import stop_pool

        stop_pool(self._pool)


class RayBackend:
    """Ray tasks: on the cluster at ``RAY_ADDRESS`` when it is set, else on a Ray of this
    command's own sized by ``workers`` (never on a head that happens to run on this machine).
    Shut down on close (also after Ctrl-C), so no Ray process of ours outlives the command."""

    @staticmethod
    def check() -> None:
        """Raise ValueError unless Ray is installed."""
        try:
            import ray  # noqa: F401
        except ImportError:
            raise ValueError("--backend ray needs Ray: pip install 'trackstar[ray]'") from None

    def __init__(self, workers: int) -> None:
        import ray

        self._ray = ray
        address = os.environ.get("RAY_ADDRESS", "").strip()
        options = {"include_dashboard": False, "log_to_driver": False, "configure_logging": False}
        if address:
            _connect(ray, address, options)
        else:
            ray.init(address="local", num_cpus=workers, **options)
        self.workers = int(ray.cluster_resources().get("CPU", workers))
        self._remote: dict = {}

    def submit(self, fn, *args):
        task = self._remote.setdefault(fn, self._ray.remote(fn))
        return task.remote(*args)

    def finished(self, handles) -> list:
        return self._ray.wait(list(handles), num_returns=1)[0]

    def result(self, handle):
        return self._ray.get(handle)

    def close(self) -> None:
        self._ray.shutdown()


CONNECT_TIMEOUT_S = 25.0  # Ray itself retries a head that does not answer for ever
RAY_PORT = 6379  # `ray start --head`'s default
_AUTH_HINT = ("; `ray start` of Ray 2.59 and later wants token authentication: set "
              "RAY_AUTH_MODE=token here and the cluster's token (docs/studies.md)")


def _connect(ray, address: str, options: dict) -> None:
    """`ray.init` on ``address`` within CONNECT_TIMEOUT_S, else ValueError in one line naming
    the address. Ray's own complaints, printed while it retries, go to the error's hint."""
    deadline = time.monotonic() + CONNECT_TIMEOUT_S
    where = f"the Ray cluster at RAY_ADDRESS={address}"
    if address != "auto":
        try:
            socket.create_connection(_host_port(address), timeout=CONNECT_TIMEOUT_S).close()
        except OSError as exc:
            raise ValueError(f"cannot reach {where}: {exc.strerror or exc} (is `ray start "
                             f"--head` running there, and is the port open?)") from None
    failed: list[Exception] = []

    def init() -> None:
        try:
            ray.init(address=address, **options)
        except Exception as exc:  # noqa: BLE001 - Ray raises several kinds; each ends here
            failed.append(exc)

    with _stderr_captured() as said:
        thread = threading.Thread(target=init, name="ray-connect", daemon=True)
        thread.start()
        thread.join(max(deadline - time.monotonic(), 0.0))
        complaints = said() + "".join(map(str, failed))
    hint = _AUTH_HINT if "auth" in complaints.lower() else ""
    if thread.is_alive():
        raise ValueError(f"no answer from {where} within {CONNECT_TIMEOUT_S:.0f} s{hint}")
    if failed:
        said_ray = str(failed[0]).strip()
        first = said_ray.splitlines()[0] if said_ray else type(failed[0]).__name__
        raise ValueError(f"cannot connect to {where}: {first}{hint}")


def _host_port(address: str) -> tuple[str, int]:
    """``host:port`` (or ``ray://host:port``, ``[::1]:port``; the port defaults to Ray's)."""
    rest = address.removeprefix("ray://").rstrip("/")
    host, sep, port = rest.rpartition(":")
    if not sep or "]" in port:
        host, port = rest, str(RAY_PORT)
    if not port.isdigit():
        raise ValueError(f"RAY_ADDRESS={address} is not HOST:PORT (for example "
                         f"head.example.edu:{RAY_PORT})")
    return host.strip("[]"), int(port)


@contextmanager
def _stderr_captured():
    """Send this process's stderr (file descriptor 2, where Ray's C++ core logs) and Ray's
    Python warnings to a file meanwhile; yields a function that reads what was written."""
    ray_log = logging.getLogger("ray")
    level, saved = ray_log.level, os.dup(2)
    ray_log.setLevel(logging.ERROR)

    def said() -> str:
        sink.seek(0)
        return sink.read().decode(errors="replace")

    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield said
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            ray_log.setLevel(level)


BACKENDS = {"local": LocalBackend, "ray": RayBackend}


def open_backend(name: str, workers: int):
    return BACKENDS[name](workers)
