"""Where a study's runs execute: this machine's process pool, or a Ray cluster.

Both take a task (a function and its arguments), hand back a handle, and say which handles are
done; the driver alone stores results, so the database, CSV, report and resume behave the same
on either. Scenario data travel with the tasks: a Ray node needs no shared file system.
The pool's modules load with a pool: every command line names the backends.
"""

from __future__ import annotations

import os

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
    """The Ray cluster at ``RAY_ADDRESS``, else a local Ray of ``workers`` CPUs; shut down on
    close (also after Ctrl-C), so no Ray process outlives the command."""

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
        address = os.environ.get("RAY_ADDRESS")
        ray.init(address=address or None, num_cpus=None if address else workers,
                 include_dashboard=False, log_to_driver=False, configure_logging=False)
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


BACKENDS = {"local": LocalBackend, "ray": RayBackend}


def open_backend(name: str, workers: int):
    return BACKENDS[name](workers)
