"""The `Studies` folder: the server's parameter studies, their progress and their reports.

A study runs on the server (POST /api/v1/studies, or `trackstar study` for a local one); the
studio lists them and hands their self-contained report or their table to the browser as a
download, so it opens wherever the browser is, whatever host name the API has.
"""

from __future__ import annotations

import httpx

__all__ = ["StudiesView"]

NONE = "—"


class StudiesView:
    """The folder's widgets and the list they show; the only writer of both."""

    def __init__(self, gui, client, api_url: str, notify) -> None:
        self.client, self.api_url, self.notify = client, api_url, notify
        self._rows: dict[str, dict] = {}  # dropdown label → the server's status of the study
        with gui.add_folder("Studies", expand_by_default=False):
            self.choice = gui.add_dropdown("Study", (NONE,))
            self.refresh = gui.add_button("Refresh list")
            self.report = gui.add_button("Download report")
            self.table = gui.add_button("Download results (CSV)")
            self.status = gui.add_markdown("Studies run on the server: POST /api/v1/studies "
                                           "(docs/studies.md).")
        self.refresh.on_click(lambda _: self.load())
        self.report.on_click(lambda _: self._download("report.html", "html"))
        self.table.on_click(lambda _: self._download("results.csv", "csv"))
        self.choice.on_update(lambda _: self._show())

    def load(self) -> None:
        """Fetch the list from the server (newest last)."""
        try:
            r = httpx.get(f"{self.api_url}/studies", timeout=10.0)
            r.raise_for_status()
            studies = r.json()
        except (httpx.HTTPError, ValueError) as exc:
            self.notify("Studies not listed", f"the server's studies: {exc}")
            return
        self._rows = {f"{s['name']} ({s['id']})": s for s in studies}
        self.choice.options = tuple(self._rows) or (NONE,)
        self.choice.value = self.choice.options[-1]
        self._show()

    def _show(self) -> None:
        s = self._rows.get(self.choice.value)
        self.status.content = (NONE if s is None else
                               f"**{s['status']}**: {s['done']} of {s['total']} runs "
                               f"({s['failed']} failed, {s['skipped']} resumed)")

    def _download(self, name: str, suffix: str) -> None:
        study = self._rows.get(self.choice.value)
        if study is None:
            self.notify("No study", "press Refresh list and choose a study")
            return
        study_id = study["id"]
        try:
            r = httpx.get(f"{self.api_url}/studies/{study_id}/{name}", timeout=120.0)
            r.raise_for_status()
        except httpx.HTTPError as exc:
            self.notify("Not downloaded", f"{name} of study {study_id}: {exc}")
            return
        self.client.send_file_download(f"{study['name']}.{suffix}", r.content,
                                       save_immediately=True)
