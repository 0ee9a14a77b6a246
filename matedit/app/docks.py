"""The main window's dockable panels: which panel goes where, their default sizes, and the
Lights dock's title (an '&' drawn as itself). The Textures browser is a tab beside the
Library; a double-click there works on the window's active canvas (`CanvasHost.canvas`).

`build_docks(window, compiler, controller, undo_group)` makes the panels and their docks on
`window` and returns them as one typed `Panels`; the window keeps it and sets nothing else.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, cast

import shiboken6
from PySide6.QtCore import Qt, QTimer
from PySide6.QtGui import QUndoGroup
from PySide6.QtWidgets import QDockWidget, QMainWindow, QScrollArea, QUndoView, QVBoxLayout, QWidget

from matedit.app.code_view import CodeView
from matedit.app.compile_service import MaterialCompiler
from matedit.app.controller import DocumentController
from matedit.app.diagnostics import DiagnosticsPanel
from matedit.app.environment import EnvironmentPanel
from matedit.app.inspector import InspectorPanel
from matedit.app.layers_panel import LayersPanel
from matedit.app.library import LibraryPanel
from matedit.app.lights_panel import LightsPanel
from matedit.app.texture_browser import TextureBrowser
from matedit.app.viewport_panel import ViewportPanel

if TYPE_CHECKING:
    from matedit.app.canvas import NodeCanvasView


class CanvasHost(Protocol):
    """What the Textures browser needs of the window: the canvas a double-click works on."""

    @property
    def canvas(self) -> NodeCanvasView: ...


LIGHTS_TITLE = "Lights & Environment"
# Default sizes at the default window size (1480x900): the viewport keeps a useful square,
# the inspector's first fields and the Lights panel's light properties show unscrolled.
SIDE_WIDTHS = (270, 430)  # left column (library, layers), right column (viewport, inspector)
RIGHT_HEIGHTS = (300, 520)  # viewport, inspector/lights
LEFT_HEIGHTS = (330, 420)  # library, layers
BOTTOM_HEIGHT = 170  # diagnostics, code, history


def add_dock(window: QMainWindow, title: str, name: str, widget: QWidget,
             area: Qt.DockWidgetArea, icon_name: str = "") -> QDockWidget:
    dock = QDockWidget(title, window)
    dock.setObjectName(name)
    dock.setWidget(widget)
    dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                     | QDockWidget.DockWidgetFeature.DockWidgetFloatable
                     | QDockWidget.DockWidgetFeature.DockWidgetClosable)
    window.addDockWidget(area, dock)
    # No icon on the View menu's entry: styles draw an icon instead of the check mark.
    dock.toggleViewAction().setCheckable(True)
    dock.setProperty("iconName", icon_name)
    return dock


@dataclass(frozen=True)
class Panels:
    """The main window's panels and the docks that hold them."""

    viewport: ViewportPanel
    inspector: InspectorPanel
    layers: LayersPanel
    library: LibraryPanel
    lights: LightsPanel
    environment: EnvironmentPanel  # on the viewport's EnvironmentChoice
    code: CodeView
    diagnostics: DiagnosticsPanel
    history: QUndoView
    viewport_dock: QDockWidget
    inspector_dock: QDockWidget
    layers_dock: QDockWidget
    library_dock: QDockWidget
    lights_dock: QDockWidget
    code_dock: QDockWidget
    diagnostics_dock: QDockWidget
    history_dock: QDockWidget
    textures: TextureBrowser
    textures_dock: QDockWidget

    def docks(self) -> list[QDockWidget]:
        """The docks in the order the View menu lists them."""
        return [self.viewport_dock, self.inspector_dock, self.layers_dock, self.library_dock,
                self.textures_dock, self.lights_dock, self.code_dock, self.diagnostics_dock,
                self.history_dock]


def _lights_host(environment: EnvironmentPanel, lights: LightsPanel) -> QScrollArea:
    host = QWidget()
    lay = QVBoxLayout(host)
    lay.setContentsMargins(0, 0, 0, 0)
    lay.setSpacing(0)
    lay.addWidget(environment)
    lay.addWidget(lights, 1)
    scroll = QScrollArea()  # its height must not squeeze the viewport above
    scroll.setObjectName("lightsScroll")
    scroll.setWidgetResizable(True)
    scroll.setFrameShape(QScrollArea.Shape.NoFrame)
    scroll.setWidget(host)
    return scroll


def build_docks(w: QMainWindow, compiler: MaterialCompiler, controller: DocumentController,
                undo_group: QUndoGroup) -> Panels:
    """The panels and their docks on the main window `w`, laid out at their default sizes."""
    L, R, B = (Qt.DockWidgetArea.LeftDockWidgetArea, Qt.DockWidgetArea.RightDockWidgetArea,
               Qt.DockWidgetArea.BottomDockWidgetArea)
    # The side columns run the window's full height; the bottom docks sit under the canvas
    # alone, so the inspector and the lights get that height.
    w.setCorner(Qt.Corner.BottomLeftCorner, L)
    w.setCorner(Qt.Corner.BottomRightCorner, R)
    viewport = ViewportPanel(compiler)
    inspector = InspectorPanel(controller)
    layers = LayersPanel(controller)
    library = LibraryPanel()
    textures = TextureBrowser(controller)
    host = cast(CanvasHost, w)  # MainWindow: its `canvas` property
    textures.canvas_of = lambda: host.canvas  # the window's active canvas, at the time
    lights = LightsPanel()
    code = CodeView(compiler)
    diagnostics = DiagnosticsPanel()
    history = QUndoView(undo_group)
    history.setEmptyLabel("<opened>")
    environment = EnvironmentPanel(viewport.environment)

    library_dock = add_dock(w, "Library", "libraryDock", library, L, "folder-add")
    textures_dock = add_dock(w, "Textures", "texturesDock", textures, L, "texture")
    layers_dock = add_dock(w, "Layers", "layersDock", layers, L, "layer")
    viewport_dock = add_dock(w, "Viewport", "viewportDock", viewport, R, "material")
    inspector_dock = add_dock(w, "Inspector", "inspectorDock", inspector, R)
    lights_dock = add_dock(w, LIGHTS_TITLE, "lightsDock", _lights_host(environment, lights), R,
                           "light")
    for sig in (lights_dock.topLevelChanged, lights_dock.dockLocationChanged,
                lights_dock.visibilityChanged):
        sig.connect(lambda *_: shiboken6.isValid(w)  # also fires while closing down
                    and QTimer.singleShot(0, w, lambda: retitle_lights(w, lights_dock)))
    diagnostics_dock = add_dock(w, "Diagnostics", "diagnosticsDock", diagnostics, B,
                                "warning")
    code_dock = add_dock(w, "GLSL", "codeDock", code, B)
    history_dock = add_dock(w, "History", "historyDock", history, B, "undo")
    w.splitDockWidget(library_dock, layers_dock, Qt.Orientation.Vertical)
    _tab_when_shown(w, library_dock, textures_dock)
    w.splitDockWidget(viewport_dock, inspector_dock, Qt.Orientation.Vertical)
    w.tabifyDockWidget(inspector_dock, lights_dock)
    inspector_dock.raise_()
    w.tabifyDockWidget(diagnostics_dock, code_dock)
    w.tabifyDockWidget(code_dock, history_dock)
    diagnostics_dock.raise_()
    retitle_lights(w, lights_dock)
    w.resizeDocks([library_dock, viewport_dock], list(SIDE_WIDTHS), Qt.Orientation.Horizontal)
    w.resizeDocks([viewport_dock, inspector_dock], list(RIGHT_HEIGHTS), Qt.Orientation.Vertical)
    w.resizeDocks([library_dock, layers_dock], list(LEFT_HEIGHTS), Qt.Orientation.Vertical)
    w.resizeDocks([diagnostics_dock], [BOTTOM_HEIGHT], Qt.Orientation.Vertical)
    return Panels(viewport, inspector, layers, library, lights, environment, code, diagnostics,
                  history, viewport_dock, inspector_dock, layers_dock, library_dock,
                  lights_dock, code_dock, diagnostics_dock, history_dock, textures,
                  textures_dock)


def _tab_when_shown(w: QMainWindow, beside: QDockWidget, dock: QDockWidget) -> None:
    """`dock` starts hidden and, shown the first time while still where it was added, is
    tabbed beside `beside` and raised. (Tabbed from the start, the left column would be
    laid out wider than the default window allows.)"""
    dock.hide()

    def shown(visible: bool) -> None:
        if not visible or not shiboken6.isValid(w):
            return
        dock.visibilityChanged.disconnect(shown)
        if not dock.isFloating() and not w.tabifiedDockWidgets(dock) and \
                w.dockWidgetArea(dock) == w.dockWidgetArea(beside):
            w.tabifyDockWidget(beside, dock)
            QTimer.singleShot(0, dock, dock.raise_)

    dock.visibilityChanged.connect(shown)


def retitle_lights(w: QMainWindow, d: QDockWidget) -> None:
    """'&' shown as itself everywhere: a dock's title bar draws its title as it is, but
    the tab of tabified docks and the View menu read '&' as a mnemonic marker."""
    tabbed = not d.isFloating() and bool(w.tabifiedDockWidgets(d))
    d.setWindowTitle(LIGHTS_TITLE.replace("&", "&&") if tabbed else LIGHTS_TITLE)
    d.toggleViewAction().setText(LIGHTS_TITLE.replace("&", "&&"))
