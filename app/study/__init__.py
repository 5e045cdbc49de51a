"""Parameter studies: a grid of planning runs described in one file, run on a process pool,
stored run by run in SQLite so that a study can be stopped and resumed at will."""
