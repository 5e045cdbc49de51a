"""Projector mode and the faded tree: the studio readable from the back of a lecture hall.

viser has no font-size setting, so a <style> in the View folder zooms the panel's content (CSS
``zoom`` on the scroll area that holds the style's marker) and the panel is widened by as much:
it lays out as before, only larger. The Planner folder and EXTEND move to the top of the panel,
Run, Pause and the Step buttons to the top of the Planner folder (the panel shows rows by their
``order``; the Planner folder and its run controls are first anyway, EXTEND comes up under
them), so the run controls stay in sight without scrolling at 1280 × 800, zoomed too.
"""

from __future__ import annotations

from app.studio._live_view import Look

__all__ = ["PANEL_PX", "Projector"]

PANEL_PX = 384  # viser's "large" control panel: 24 em of 16 px
ZOOM = 1.35  # the panel's text and controls in projector mode
SCALE = 1.8  # its lines and step labels
CSS = ("<span class='trackstar-projector'></span><style>.mantine-ScrollArea-content:has("
       f".trackstar-projector) {{ zoom: {ZOOM} }}</style>")


class Projector:
    """Owns what the View folder's checkboxes change in the panel; the session hands `look`
    to the planner run and `panel_px` to the view fit."""

    def __init__(self, gui, ui) -> None:
        self.gui, self.ui = gui, ui
        self._first = (ui.planner_folder, ui.extend_folder, ui.run, ui.pause, ui.step,
                       ui.step_node, ui.step_rewire)  # on top in projector mode, in this order
        self._orders = [h.order for h in self._first]  # where they are otherwise

    @property
    def on(self) -> bool:
        return bool(self.ui.projector.value)

    @property
    def panel_px(self) -> float:
        """The control panel's width on screen."""
        return PANEL_PX * (ZOOM if self.on else 1.0)

    @property
    def look(self) -> Look:
        return Look(scale=SCALE if self.on else 1.0, faded=bool(self.ui.fade_tree.value))

    def apply(self) -> None:
        """The panel as `Projector mode` says: its zoom and width, the order of its rows."""
        self.ui.projector_css.content = CSS if self.on else ""
        self.gui.main_panel.set_width(self.panel_px)
        for i, (h, order) in enumerate(zip(self._first, self._orders)):
            # Below every default order (a counter from 1), after the View folder (-10).
            h.order = i - len(self._first) if self.on else order
