"""A study's results: one SQLite file, written run by run, readable by others while it grows.

Each finished run is committed at once (WAL mode), so Ctrl-C, a crash or ``kill -9`` loses no
finished run and leaves a valid database. The schema (docs/studies.md) is versioned with
``PRAGMA user_version``: planning runs in ``runs`` (with ``cost_over_time``), driven runs in
``sim_runs``. Only the study's driver writes; a run that failed is stored with its
error and replaced when the study is run again.
"""

from __future__ import annotations

import csv
import datetime as dt
import io
import sqlite3
from importlib.metadata import version
from pathlib import Path

__all__ = ["COLUMNS", "TABLES", "Results", "StudyMismatch", "runs_csv"]

# 2: sim_runs splits collisions into the car's (moving) and at rest; 3: runs.polish_s
SCHEMA_VERSION = 3
KEY = ("scenario", "planner", "steering", "parameters", "budget_iterations", "budget_time_s",
       "seed")
OUTCOME = ("solved", "cost", "time_to_first_solution_s", "iterations", "nodes",
           "collision_checks", "min_clearance_m", "iterations_per_s", "polish_s", "wall_s",
           "error")
SIM_KEY = ("scenario", "parameters", "seed")
SIM_OUTCOME = ("reached", "collisions", "collisions_moving", "collisions_at_rest",
               "min_clearance_m", "time_to_goal_s", "cycle_p50_ms",
               "cycle_p99_ms", "replans", "emergency_stops", "max_lateral_error_m", "wall_s",
               "error")
COLUMNS = {"plan": ("id", "study", *KEY, *OUTCOME, "trackstar_version", "finished_at"),
           "simulate": ("id", "study", *SIM_KEY, *SIM_OUTCOME, "trackstar_version",
                        "finished_at")}
TABLES = {"plan": "runs", "simulate": "sim_runs"}

_SCHEMA = f"""
CREATE TABLE IF NOT EXISTS study (
    name TEXT PRIMARY KEY, file TEXT NOT NULL, started_at TEXT NOT NULL,
    trackstar_version TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS runs (
    id INTEGER PRIMARY KEY, study TEXT NOT NULL, scenario TEXT NOT NULL, planner TEXT NOT NULL,
    steering TEXT NOT NULL, parameters TEXT NOT NULL, budget_iterations INTEGER,
    budget_time_s REAL, seed INTEGER NOT NULL, solved INTEGER, cost REAL,
    time_to_first_solution_s REAL, iterations INTEGER, nodes INTEGER, collision_checks INTEGER,
    min_clearance_m REAL, iterations_per_s REAL, polish_s REAL, wall_s REAL, error TEXT,
    trackstar_version TEXT NOT NULL, finished_at TEXT NOT NULL);
CREATE UNIQUE INDEX IF NOT EXISTS runs_key ON runs (study, scenario, planner, steering,
    parameters, IFNULL(budget_iterations, -1), IFNULL(budget_time_s, -1), seed);
CREATE TABLE IF NOT EXISTS cost_over_time (
    run_id INTEGER NOT NULL REFERENCES runs (id) ON DELETE CASCADE, iteration INTEGER,
    t_s REAL NOT NULL, cost REAL NOT NULL);
CREATE INDEX IF NOT EXISTS cost_over_time_run ON cost_over_time (run_id);
CREATE TABLE IF NOT EXISTS sim_runs (
    id INTEGER PRIMARY KEY, study TEXT NOT NULL, scenario TEXT NOT NULL,
    parameters TEXT NOT NULL, seed INTEGER NOT NULL, reached INTEGER, collisions INTEGER,
    collisions_moving INTEGER, collisions_at_rest INTEGER, min_clearance_m REAL, time_to_goal_s REAL, cycle_p50_ms REAL, cycle_p99_ms REAL,
    replans INTEGER, emergency_stops INTEGER, max_lateral_error_m REAL, wall_s REAL,
    error TEXT, trackstar_version TEXT NOT NULL, finished_at TEXT NOT NULL,
    UNIQUE (study, scenario, parameters, seed));
PRAGMA user_version = {SCHEMA_VERSION};
"""


class StudyMismatch(ValueError):
    """The results file belongs to another study."""


class Results:
    """``DIR/results.sqlite`` of one study."""

    def __init__(self, directory: Path, study: str, kind: str, file_text: str) -> None:
        directory.mkdir(parents=True, exist_ok=True)
        self.path = directory / "results.sqlite"
        self.created = not self.path.exists()  # by this study command
        self.study = study
        self.table, self.columns = TABLES[kind], COLUMNS[kind]
        self._key = KEY if kind == "plan" else SIM_KEY
        self.version = version("trackstar")
        self._db = sqlite3.connect(self.path, isolation_level=None)
        self._db.execute("PRAGMA journal_mode = WAL")
        self._db.execute("PRAGMA foreign_keys = ON")
        _migrate(self._db)
        self._db.executescript(_SCHEMA)
        other = self._db.execute("SELECT name FROM study WHERE name != ?", (study,)).fetchone()
        if other is not None:
            self._db.close()
            raise StudyMismatch(f"{self.path} holds study '{other[0]}', not '{study}': give "
                                f"another --out")
        self._db.execute(
            "INSERT INTO study VALUES (?, ?, ?, ?) ON CONFLICT (name) DO UPDATE SET "
            "file = excluded.file", (study, file_text, _now(), self.version))

    def done(self) -> set[tuple]:
        """Keys of the runs that finished (failed runs are done again)."""
        rows = self._db.execute(f"SELECT {', '.join(self._key)} FROM {self.table} WHERE "
                                f"study = ? AND error IS NULL", (self.study,))
        return set(rows)

    def add(self, run, outcome: dict, cost_over_time: list) -> None:
        """Store one run (and a planning run's cost curve) in one transaction, replacing a
        failed attempt."""
        match = " AND ".join(f"{k} IS ?" for k in self._key)
        outcomes = self.columns[2 + len(self._key):-2]
        with self._db:  # BEGIN … COMMIT
            self._db.execute("BEGIN")
            self._db.execute(f"DELETE FROM {self.table} WHERE study = ? AND {match}",
                             (self.study, *run.key))
            cur = self._db.execute(
                f"INSERT INTO {self.table} ({', '.join(self.columns[1:])}) VALUES "
                f"({', '.join('?' * (len(self.columns) - 1))})",
                (self.study, *run.key, *(outcome.get(c) for c in outcomes), self.version,
                 _now()))
            self._db.executemany("INSERT INTO cost_over_time VALUES (?, ?, ?, ?)",
                                 [(cur.lastrowid, *row) for row in cost_over_time])

    def count(self) -> tuple[int, int]:
        """(runs stored, of which failed)."""
        return self._db.execute(f"SELECT COUNT(*), COUNT(error) FROM {self.table} WHERE "
                                f"study = ?", (self.study,)).fetchone()

    def write_csv(self, path: Path) -> None:
        """The runs table as CSV (`runs_csv`)."""
        path.write_text(runs_csv(self._db, self.table), encoding="utf-8")

    def close(self) -> None:
        self._db.close()

    def discard(self) -> None:
        """Close, and delete the file (with its WAL files) if this command created it: for a
        study that stored nothing because it could not start, so no empty file is left."""
        self.close()
        for suffix in ("", "-wal", "-shm") if self.created else ():
            self.path.with_name(self.path.name + suffix).unlink(missing_ok=True)


def _migrate(db: sqlite3.Connection) -> None:
    """Bring a results file of an older schema up to date (columns added, none removed)."""
    old = db.execute("PRAGMA user_version").fetchone()[0]
    has_sim = db.execute("SELECT 1 FROM sqlite_master WHERE name = 'sim_runs'").fetchone()
    if has_sim and old < 2:
        for column in ("collisions_moving", "collisions_at_rest"):
            db.execute(f"ALTER TABLE sim_runs ADD COLUMN {column} INTEGER")
    has_runs = db.execute("SELECT 1 FROM sqlite_master WHERE name = 'runs'").fetchone()
    if has_runs and old < 3:
        db.execute("ALTER TABLE runs ADD COLUMN polish_s REAL")


def _now() -> str:
    return dt.datetime.now(dt.UTC).isoformat(timespec="seconds")


def runs_csv(db: sqlite3.Connection, table: str) -> str:
    """A runs table as CSV: a header of the column names, one line per run."""
    kind = next(k for k, t in TABLES.items() if t == table)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS[kind])
    writer.writerows(db.execute(f"SELECT {', '.join(COLUMNS[kind])} FROM {table} ORDER BY id"))
    return out.getvalue()
