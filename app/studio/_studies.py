"""The `Studies` folder: the server's parameter studies, their progress and their reports.

A study runs on the server (POST /api/v1/studies, or `trackstar study` for a local one); the
studio lists them, opens a study's report in a window beside the scene and hands the report or
the table to the browser as a download. The studio fetches them from the API itself, so they
open wherever the browser is, whatever host name the API has: the report is self-contained
(every image inline), shown in a sandboxed frame of its own.
"""

from __future__ import annotations

import html

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
            self.open = gui.add_button("Open report")
            self.report = gui.add_button("Download report")
            self.table = gui.add_button("Download results (CSV)")
            self.status = gui.add_markdown("Studies run on the server: POST /api/v1/studies "
                                           "(docs/studies.md).")
        self.gui = gui
        self._window = None  # the open report's floating panel
        self.refresh.on_click(lambda _: self.load())
        self.open.on_click(lambda _: self._open())
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

    def _fetch(self, name: str, failed: str) -> tuple[dict, bytes] | None:
        """The chosen study and its file ``name`` from the API; None (and a notice) if not."""
        study = self._rows.get(self.choice.value)
        if study is None:
            self.notify("No study", "press Refresh list and choose a study")
            return None
        try:
            r = httpx.get(f"{self.api_url}/studies/{study['id']}/{name}", timeout=120.0)
            r.raise_for_status()
        except httpx.HTTPError as exc:
            self.notify(failed, f"{name} of study {study['id']}: {exc}")
            return None
        return study, r.content

    def _download(self, name: str, suffix: str) -> None:
        fetched = self._fetch(name, "Not downloaded")
        if fetched is not None:
            study, content = fetched
            self.client.send_file_download(f"{study['name']}.{suffix}", content,
                                           save_immediately=True)

    def _open(self) -> None:
        """The report in a floating window over the scene (one at a time), its page in a
        sandboxed frame: scripts of the report cannot reach the studio."""
        fetched = self._fetch("report.html", "Report not opened")
        if fetched is None:
            return
        study, content = fetched
        if self._window is not None:
            self._window.remove()
        self._window = self.gui.add_panel()
        with self._window.add_tab(f"Report: {study['name']}"):
            self.gui.add_html(
                f'<iframe title="report of {html.escape(study["name"])}" sandbox '
                f'srcdoc="{html.escape(content.decode("utf-8", "replace"), quote=True)}" '
                'style="width:100%;height:70vh;border:0;background:white"></iframe>')
        self._window.float(x=20, y=20, width=900, height=620)
