"""The server's data: one SQLite file (WAL) with uploaded tracks, scenarios, batch jobs,
simulations and studies (simulation logs and each study's results directory are beside it,
see `jobs.Planning`).

Schema changes are appended to `MIGRATIONS`; `schema_version` records how many have run, so a
data directory from an older release is upgraded on start and never rebuilt. One connection is
shared by the request threads and the event loop behind a lock: every statement is short.
"""

from __future__ import annotations

import json
import secrets
import sqlite3
import threading
import time
from pathlib import Path
from typing import Any

__all__ = ["UNFINISHED", "Store"]

UNFINISHED = ("queued", "running")

MIGRATIONS = [
    """
    CREATE TABLE tracks (id TEXT PRIMARY KEY, name TEXT NOT NULL, svg BLOB NOT NULL, path TEXT,
                         unit TEXT, closed INTEGER NOT NULL, length_m REAL NOT NULL,
                         width_m REAL NOT NULL, created REAL NOT NULL);
    CREATE TABLE scenarios (id TEXT PRIMARY KEY, name TEXT NOT NULL, body TEXT NOT NULL,
                            created REAL NOT NULL);
    CREATE TABLE jobs (id TEXT PRIMARY KEY, status TEXT NOT NULL, total INTEGER NOT NULL,
                       error TEXT, created REAL NOT NULL);
    CREATE TABLE job_results (job_id TEXT NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
                              idx INTEGER NOT NULL, body TEXT NOT NULL,
                              PRIMARY KEY (job_id, idx));
    """,
    """
    CREATE TABLE simulations (id TEXT PRIMARY KEY, status TEXT NOT NULL, scenario TEXT NOT NULL,
                              settings TEXT NOT NULL, summary TEXT, error TEXT,
                              created REAL NOT NULL);
    """,
    """
    CREATE TABLE studies (id TEXT PRIMARY KEY, name TEXT NOT NULL, status TEXT NOT NULL,
                          body TEXT NOT NULL, total INTEGER NOT NULL,
                          skipped INTEGER NOT NULL DEFAULT 0, error TEXT,
                          created REAL NOT NULL);
    """,
]


def new_id() -> str:
    return secrets.token_hex(6)


class Store:
    """Rows in, plain dicts out; ids are generated here."""

    def __init__(self, path: Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        self.path = path
        self._db = sqlite3.connect(path, check_same_thread=False, isolation_level=None)
        self._db.row_factory = sqlite3.Row
        self._lock = threading.Lock()
        self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute("PRAGMA synchronous=NORMAL")
        self._db.execute("PRAGMA foreign_keys=ON")
        self._migrate()

    def _migrate(self) -> None:
        with self._lock:
            self._db.execute("CREATE TABLE IF NOT EXISTS schema_version (version INTEGER)")
            row = self._db.execute("SELECT version FROM schema_version").fetchone()
            version = row[0] if row else 0
            if version > len(MIGRATIONS):
                raise RuntimeError(f"the database is from a newer trackstar (schema {version})")
            for step in MIGRATIONS[version:]:
                self._db.executescript(f"BEGIN; {step}; COMMIT;")
            self._db.execute("DELETE FROM schema_version")
            self._db.execute("INSERT INTO schema_version VALUES (?)", (len(MIGRATIONS),))

    def _all(self, sql: str, *args) -> list[dict]:
        with self._lock:
            return [dict(r) for r in self._db.execute(sql, args).fetchall()]

    def _one(self, sql: str, *args) -> dict | None:
        rows = self._all(sql, *args)
        return rows[0] if rows else None

    def _write(self, sql: str, *args) -> int:
        with self._lock:
            return self._db.execute(sql, args).rowcount

    def close(self) -> None:
        with self._lock:
            self._db.close()

    # tracks
    def add_track(self, name: str, svg: bytes, path: str | None, unit: str | None,
                  closed: bool, length_m: float, width_m: float) -> str:
        track_id = new_id()
        self._write("INSERT INTO tracks VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)", track_id, name, svg,
                    path, unit, int(closed), length_m, width_m, time.time())
        return track_id

    def tracks(self) -> list[dict]:
        return self._all("SELECT id, name, closed, length_m, width_m FROM tracks ORDER BY created")

    def track(self, track_id: str) -> dict | None:
        return self._one("SELECT * FROM tracks WHERE id = ?", track_id)

    def delete_track(self, track_id: str) -> bool:
        return self._write("DELETE FROM tracks WHERE id = ?", track_id) > 0

    # scenarios
    def add_scenario(self, name: str, body: dict) -> str:
        scenario_id = new_id()
        self._write("INSERT INTO scenarios VALUES (?, ?, ?, ?)", scenario_id, name,
                    json.dumps(body), time.time())
        return scenario_id

    def scenarios(self) -> list[dict]:
        rows = self._all("SELECT id, name, body FROM scenarios ORDER BY created")
        return [_scenario(r) for r in rows]

    def scenario(self, scenario_id: str) -> dict | None:
        row = self._one("SELECT id, name, body FROM scenarios WHERE id = ?", scenario_id)
        return _scenario(row) if row else None

    def delete_scenario(self, scenario_id: str) -> bool:
        return self._write("DELETE FROM scenarios WHERE id = ?", scenario_id) > 0

    # jobs
    def add_job(self, total: int) -> str:
        job_id = new_id()
        self._write("INSERT INTO jobs VALUES (?, 'queued', ?, NULL, ?)", job_id, total,
                    time.time())
        return job_id

    def job(self, job_id: str) -> dict | None:
        row = self._one("SELECT id, status, total, error, "
                        "(SELECT COUNT(*) FROM job_results WHERE job_id = jobs.id) AS done "
                        "FROM jobs WHERE id = ?", job_id)
        if row is not None:
            row["results"] = [json.loads(r["body"]) for r in self._all(
                "SELECT body FROM job_results WHERE job_id = ? ORDER BY idx", job_id)]
        return row

    def set_job_status(self, job_id: str, status: str, error: str | None = None) -> None:
        """Move an unfinished job on; a finished one (done, failed, cancelled) stays as it is."""
        self._write(f"UPDATE jobs SET status = ?, error = ? WHERE id = ? AND status IN "
                    f"{UNFINISHED}", status, error, job_id)

    def add_result(self, job_id: str, idx: int, body: dict[str, Any]) -> None:
        self._write("INSERT INTO job_results VALUES (?, ?, ?)", job_id, idx, json.dumps(body))

    def fail_unfinished(self, error: str) -> list[str]:
        """Mark every queued or running job and simulation failed (at shutdown, and on start
        after a crash)."""
        ids = [r["id"] for r in self._all(f"SELECT id FROM jobs WHERE status IN {UNFINISHED}")]
        for job_id in ids:
            self.set_job_status(job_id, "failed", error)
        sims = [r["id"] for r in self._all(
            f"SELECT id FROM simulations WHERE status IN {UNFINISHED}")]
        for sim_id in sims:
            self.set_simulation(sim_id, "failed", error=error)
        return ids + sims

    # simulations
    def add_simulation(self, scenario: str, settings: dict[str, Any]) -> str:
        sim_id = new_id()
        self._write("INSERT INTO simulations VALUES (?, 'queued', ?, ?, NULL, NULL, ?)", sim_id,
                    scenario, json.dumps(settings), time.time())
        return sim_id

    def simulation(self, sim_id: str) -> dict | None:
        row = self._one("SELECT id, status, scenario, settings, summary, error FROM simulations "
                        "WHERE id = ?", sim_id)
        if row is not None:
            for key in ("settings", "summary"):
                row[key] = json.loads(row[key]) if row[key] is not None else None
        return row

    def set_simulation(self, sim_id: str, status: str, *, summary: dict | None = None,
                       error: str | None = None) -> None:
        """Move an unfinished simulation on; a finished one stays as it is."""
        self._write(f"UPDATE simulations SET status = ?, summary = ?, error = ? WHERE id = ? "
                    f"AND status IN {UNFINISHED}", status,
                    json.dumps(summary) if summary is not None else None, error, sim_id)


    # studies: the rows say what was asked and how far it got; the runs are in each study's
    # own results.sqlite (app.study.results)
    def add_study(self, name: str, body: dict[str, Any], total: int) -> str:
        study_id = new_id()
        self._write("INSERT INTO studies VALUES (?, ?, 'queued', ?, ?, 0, NULL, ?)", study_id,
                    name, json.dumps(body), total, time.time())
        return study_id

    def study(self, study_id: str) -> dict | None:
        row = self._one("SELECT * FROM studies WHERE id = ?", study_id)
        if row is not None:
            row["body"] = json.loads(row["body"])
        return row

    def studies(self) -> list[dict]:
        return self._all("SELECT id, name, status, total, skipped, error FROM studies "
                         "ORDER BY created")

    def unfinished_studies(self) -> list[dict]:
        return [self.study(r["id"]) for r in self._all(
            f"SELECT id FROM studies WHERE status IN {UNFINISHED} ORDER BY created")]

    def set_study(self, study_id: str, status: str, *, skipped: int | None = None,
                  error: str | None = None) -> None:
        """Move an unfinished study on; a finished one stays as it is."""
        self._write(f"UPDATE studies SET status = ?, skipped = IFNULL(?, skipped), error = ? "
                    f"WHERE id = ? AND status IN {UNFINISHED}", status, skipped, error,
                    study_id)


def _scenario(row: dict) -> dict:
    return {"id": row["id"], "name": row["name"], "source": "upload",
            "scenario": json.loads(row["body"])}
