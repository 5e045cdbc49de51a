"""A real `trackstar serve` subprocess for the server tests: started on free ports, stopped
by signal, with its start lines parsed for the real ports."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import threading
import time
from pathlib import Path

import httpx

START_TIMEOUT_S = 60  # cold worker start on a loaded 2-core runner; normally ~2 s


def free_port() -> int:
    """A port nothing listens on now (the OS's pick)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Server:
    def __init__(self, data_dir: Path, *args: str, env: dict | None = None,
                 command: list[str] | None = None, warm: bool = True) -> None:
        """``warm``: wait until /health says the kernels are loaded (the server answers before:
        it loads them in the background)."""
        cmd = command or ["trackstar", "serve", "--port", "0", "--ui-port", "0",
                          "--data-dir", str(data_dir), *args]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True, env={**os.environ, **(env or {})})
        self.lines: list[str] = []
        self.err: list[str] = []
        started = threading.Event()

        def read(stream, sink):
            for line in stream:
                sink.append(line.rstrip("\n"))
                if line.startswith("UI: "):
                    started.set()
            started.set()  # the process ended

        threading.Thread(target=read, args=(self.proc.stdout, self.lines), daemon=True).start()
        threading.Thread(target=read, args=(self.proc.stderr, self.err), daemon=True).start()
        if not started.wait(START_TIMEOUT_S) or self.proc.poll() is not None:
            self.stop()
            raise RuntimeError(f"server did not start: {self.lines} {self.err}")
        api = next(m for line in self.lines if (m := re.fullmatch(r"API: http://(.+):(\d+)/docs",
                                                                  line)))
        ui = next(m for line in self.lines if (m := re.fullmatch(r"UI: http://(.+):(\d+)/",
                                                                 line)))
        self.port, self.ui_port = int(api[2]), int(ui[2])
        self.url = f"http://127.0.0.1:{self.port}"
        self.client = httpx.Client(base_url=self.url + "/api/v1", timeout=60)
        self.root = httpx.Client(base_url=self.url, timeout=60)
        deadline = time.monotonic() + START_TIMEOUT_S
        while warm and self.get("/health").json()["status"] != "ok":
            if time.monotonic() > deadline:
                self.stop()
                raise RuntimeError(f"the kernels did not load: {self.err}")
            time.sleep(0.05)

    def get(self, path: str, **kw) -> httpx.Response:
        return self.root.get(path, **kw)

    def stop(self, sig: int = signal.SIGTERM) -> float:
        """Signal the server and wait for it; returns the seconds it took to exit."""
        start = time.monotonic()
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        return time.monotonic() - start

    def wait_job(self, job_id: str, timeout: float = 60) -> dict:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            job = self.client.get(f"/jobs/{job_id}").json()
            if job["status"] not in ("queued", "running"):
                return job
            time.sleep(0.1)
        raise TimeoutError(f"job {job_id} still {job['status']} after {timeout} s")

    def workers_cpu_s(self) -> float:
        """CPU seconds used so far by the server's child processes (its planning workers)."""
        tick = os.sysconf("SC_CLK_TCK")
        total = 0
        for stat in Path("/proc").glob("[0-9]*/stat"):
            try:
                fields = stat.read_text().rsplit(")", 1)[1].split()
            except OSError:  # the process has ended meanwhile
                continue
            if int(fields[1]) == self.proc.pid:  # its parent
                total += int(fields[11]) + int(fields[12])  # utime, stime
        return total / tick
