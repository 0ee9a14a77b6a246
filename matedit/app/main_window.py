"""The main window: canvas tabs in the centre, dockable panels around it, menus, status bar.

Panels are wired to the active tab's controller (inspector, history, diagnostics)
or to the material's (viewport, layers, code). Dock layout and window geometry
are kept in QSettings and restored at the next start.

The window is composed here and only here: `build_docks` returns the `Panels`,
`install_menus` the `Menus`, `Instances` the instance editor's part; each takes what it
needs of the window as a typed Protocol, and no other module sets an attribute on it.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QTimer
from PySide6.QtGui import QCloseEvent, QUndoGroup
from PySide6.QtWidgets import QApplication, QLabel, QMainWindow

from matedit.app.canvas import NodeCanvasView
from matedit.app.canvas.actions import PaletteOnTab
from matedit.app.canvas.placement import make_room
from matedit.app.canvas_tabs import CanvasTab, CanvasTabs
from matedit.app.compile_service import MaterialCompiler
from matedit.app.controller import DocumentController
from matedit.app.docks import Panels, build_docks
from matedit.app.document_actions import DocumentActions, document_title, new_material
from matedit.app.documents import DocumentTabs
from matedit.app.export_dialog import ExportDialog
from matedit.app.help import NodeDocs, ShortcutReference, show_about
from matedit.app.instance_editor import InstanceEditor, Instances
from matedit.app.layout import WindowLayout
from matedit.app.menus import Menus, install_menus
from matedit.app.node_preview import PreviewTarget
from matedit.app.problems import ProblemsModel
from matedit.app.startup import after_first_frame
from matedit.app.stats_dock import install_stats
from matedit.resources import graphs_dir

SAMPLE = "materials/rusty_painted_metal.json"


def sample_path() -> Path:
    return graphs_dir() / SAMPLE


class MainWindow(QMainWindow):
    def __init__(self, path: str | Path | None = None, *, sample: bool = True,
                 restore_layout: bool = True, start: bool = True) -> None:
        super().__init__()
        self.setObjectName("MainWindow")
        self.resize(1480, 900)
        self.setDockNestingEnabled(True)
        self.controller = DocumentController(new_material(), self)
        self.actions = DocumentActions(self, self.controller)
        self.compiler = MaterialCompiler(self.controller, self)
        self.undo_group = QUndoGroup(self)

        self.tabs = CanvasTabs(self.controller, self.actions, self.undo_group, self)
        self.documents = DocumentTabs(self.controller, self.actions, self)
        self.documents.opening.connect(self.tabs.defer_builds)
        self.setCentralWidget(self.documents.over(self.tabs))
        self.panels: Panels = build_docks(self, self.compiler, self.controller,
                                          self.undo_group)
        p = self.panels  # the panels the window's own code reaches most, by name
        self.viewport, self.inspector, self.layers = p.viewport, p.inspector, p.layers
        self.library, self.lights, self.environment = p.library, p.lights, p.environment
        self.code, self.diagnostics = p.code, p.diagnostics
        self.problems = ProblemsModel(self.compiler, self.viewport, self)
        self.stats = install_stats(self, self.controller, self.layers, self.problems,
                                   self.tabs.material.canvas.cost_overlay, p.history_dock)
        self.menus: Menus = install_menus(self, self, [*p.docks(), self.stats.dock])
        for a in (self.viewport.follow_action, self.viewport.ab_action):
            self.menus.view.insertAction(self.menus.snap, a)
        self.menus.view.insertMenu(self.menus.snap, self.viewport.ab_menu)
        self._build_status()
        self._connect()
        # File › New Instance, the Parameters dock, the Library's instances
        self.instances = Instances(self, self, self.menus.file, p.library, p.inspector_dock)
        self.viewport.instances_of = self.instances.instances_of_open
        self.actions.open_instance = self.open_instance
        self.layout_state = WindowLayout(self, self.viewport, self.lights, self.menus.snap)
        if restore_layout:
            self.restore_layout()
        self.undo_group.setActiveStack(self.controller.undo_stack)
        self._on_active(self.tabs.active)
        self._retitle()
        self._shortcuts: ShortcutReference | None = None
        self._docs: NodeDocs | None = None
        self._tab_filter = PaletteOnTab(self, lambda: self.canvas)  # Tab over the canvas
        QApplication.instance().installEventFilter(self._tab_filter)
        self.actions.open_recovered_function = lambda e, doc: self.tabs.open_function(
            e.document, self.tabs.material, recovered=doc)
        self.actions.open_recovered_material = self.documents.open_recovered
        self.actions.open_function = lambda p: self.tabs.open_function(p, self.tabs.material)
        self.actions.preview_settings = self.viewport.document_preview
        self.startup = after_first_frame(self.viewport.view, self.library.list_in_turns)
        if start:
            self.actions.start(path, sample_path() if sample else None)
            self.compiler.recompile()

    def _build_status(self) -> None:
        sb = self.statusBar()
        self.compile_label = QLabel("")
        self.count_label = QLabel("")
        sb.addPermanentWidget(self.count_label)
        sb.addPermanentWidget(self.compile_label)

    def _connect(self) -> None:
        c = self.controller
        c.undo_stack.cleanChanged.connect(self._clean_changed)
        c.undoStackReplaced.connect(self._undo_stack_replaced)
        c.documentReplaced.connect(self._document_replaced)
        c.analysed.connect(lambda _a: self._refresh_problems())
        self.actions.opened.connect(lambda _p: self._retitle())
        self.actions.saved.connect(lambda p: self.status(f"saved {p}"))
        self.actions.saved.connect(lambda _p: self._retitle())  # Save As of a clean document
        self.actions.message.connect(self.status)
        self.problems.changed.connect(self._refresh_problems)
        self.viewport.statusMessage.connect(self.status)
        self.viewport.environmentChanged.connect(lambda s: self.status(f"environment: {s}"))
        self.tabs.materialOpenRequested.connect(self.open_material)
        self.tabs.docsRequested.connect(self.show_docs)
        self.inspector.docsRequested.connect(self.show_docs)
        self.inspector.textureSlotChosen.connect(
            lambda nid, port, path: self.canvas.fill_texture_slot(nid, port, path))
        self.tabs.previewRequested.connect(
            lambda nid, port: self.compiler.set_preview(PreviewTarget(nid, port)))
        self.tabs.activeChanged.connect(self._on_active)
        self.tabs.selectionChanged.connect(self.inspector.set_selection)
        self.tabs.selectionChanged.connect(self._follow_selection)
        self.tabs.message.connect(self.status)
        self.tabs.functionSaved.connect(lambda _p: self.controller.reanalyse())
        self.inspector.message.connect(self.status)
        self.inspector.functionOpenRequested.connect(
            lambda p: self.tabs.open_function(p, self.tabs.active))
        self.layers.message.connect(self.status)
        self.layers.make_room = lambda nid: make_room(self.tabs.material.canvas.scene(), nid)
        self.documents.follow_undo(self.undo_group, lambda: self.tabs.active.controller)
        self.layers.layerSelected.connect(self._layer_selected)
        self.library.materialOpenRequested.connect(self.open_material)
        self.library.functionOpenRequested.connect(
            lambda p: self.tabs.open_function(p, self.tabs.material))
        self.library.layerAddRequested.connect(
            lambda p: self.layers.add_layer_file(Path(p)))
        self.diagnostics.nodeActivated.connect(self.select_node)
        self.lights.lightsChanged.connect(self.viewport.set_lights)
        QTimer.singleShot(0, self, self._sync_lights)

    def _sync_lights(self) -> None:
        """The lights panel starts with the renderer's default lights once GL is up."""
        lights = self.viewport.renderer_lights()
        if lights is None:
            QTimer.singleShot(200, self, self._sync_lights)
        elif lights and not self.lights.lights:
            self.lights.set_lights(lights)

    # --- documents -------------------------------------------------------------------------
    def open_material(self, path: str | Path) -> bool:
        """A material in a document tab of its own (the tab that has it, if one does)."""
        return self.documents.open(path)

    # --- help ------------------------------------------------------------------------------
    def show_shortcuts(self) -> ShortcutReference:
        if self._shortcuts is None:
            self._shortcuts = ShortcutReference(self)
        self._shortcuts.show()
        self._shortcuts.raise_()
        return self._shortcuts

    def show_docs(self, kind: str = "") -> NodeDocs:
        """The node reference, at `kind` (empty: where it was, or its first kind)."""
        if self._docs is None:
            self._docs = NodeDocs(kind, self)
        elif kind:
            self._docs.show_kind(kind)
        self._docs.show()
        self._docs.raise_()
        return self._docs

    def show_about(self) -> None:
        show_about(self, self.viewport.gl_renderer())

    def save_viewport_image(self) -> bool:
        return self.viewport.save_image_dialog()

    # --- instances -------------------------------------------------------------------------
    def open_instance(self, path: str) -> InstanceEditor | None:
        return self.instances.open(path)

    def create_instance(self, parent_file: str | Path, path: str | Path) -> InstanceEditor:
        return self.instances.create(parent_file, path)

    def save_active(self) -> bool:
        done = self.documents.save_active()  # an instance tab's editor
        return done if done is not None else self.tabs.active.actions.save()

    def save_active_as(self) -> bool:
        editor = self.documents.current.editor
        return editor.save_as() if editor is not None else self.tabs.active.actions.save_as()

    def export_shaders(self) -> None:
        if self.compiler.current is None:
            self.status("the material does not compile: see Diagnostics")
        dlg = ExportDialog(self.controller.document, self.controller.resolver, self)
        if dlg.exec() and dlg.written:
            self.status(f"exported {len(dlg.written)} files to {dlg.written[0].parent}")

    def _document_replaced(self) -> None:
        self._retitle()
        self.viewport.set_preview(self.controller.document.preview,
                                  self.controller.document.path)
        self.inspector.show_node(None)

    def _undo_stack_replaced(self, old) -> None:
        old.cleanChanged.disconnect(self._clean_changed)
        self.controller.undo_stack.cleanChanged.connect(self._clean_changed)

    def _clean_changed(self, _clean: bool) -> None:
        self._retitle()

    def _retitle(self) -> None:
        doc = self.controller.document
        name = document_title(doc)
        self.setWindowTitle(f"{name}[*] — matedit")
        self.setWindowModified(self.controller.dirty)
        g = doc.graph
        self.count_label.setText(f"{len(g.nodes)} nodes · {len(g.links)} links")

    # --- active tab ------------------------------------------------------------------------
    def _on_active(self, tab: CanvasTab) -> None:
        self.inspector.set_controller(tab.controller)
        self._refresh_problems()

    def select_node(self, node_id: str) -> None:
        canvas = self.tabs.active.canvas
        canvas.select_nodes([node_id])
        canvas.frame_selection()
        self.inspector.show_node(node_id)
        self.panels.inspector_dock.show()
        self.panels.inspector_dock.raise_()

    def _follow_selection(self, node_ids: list[str]) -> None:
        """View › Follow Selection: the material tab's selected node in the viewport."""
        m = self.tabs.material
        if self.tabs.active is m:
            self.viewport.follow_selection(list(node_ids), m.canvas.previewable_output)

    def _layer_selected(self, stack_id: str) -> None:
        if self.tabs.active is not self.tabs.material:
            return
        self.tabs.material.canvas.select_nodes([stack_id])
        self.inspector.show_node(stack_id)

    @property
    def canvas(self) -> NodeCanvasView:
        """The active tab's canvas."""
        return self.tabs.active.canvas

    def open_palette(self) -> None:
        self.canvas.open_palette()

    # --- problems --------------------------------------------------------------------------
    def _refresh_problems(self) -> None:
        tab = self.tabs.active
        m = self.tabs.material
        self.compile_label.setText(self.problems.status)
        self.diagnostics.set_problems(self.problems.for_tab(tab.controller.analysis, tab is m),
                                      self.problems.empty_text(tab is m))
        tab.canvas.set_node_errors(self.diagnostics.errors_by_node())
        if tab is not m:
            m.canvas.set_node_errors(self.problems.material_errors())
        n = sum(1 for p in self.diagnostics.problems if p.severity == "error")  # the rows
        self.panels.diagnostics_dock.setWindowTitle("Diagnostics" + (f" ({n})" if n else ""))
        self._retitle()

    def status(self, text: str) -> None:
        self.statusBar().showMessage(text, 6000)

    # --- layout ----------------------------------------------------------------------------
    def restore_layout(self) -> None:
        """Window geometry, docks, the viewport's view, the light rig and grid snapping."""
        self.layout_state.restore()

    def save_layout(self) -> None:
        self.layout_state.save()

    def reset_layout(self) -> None:
        self.layout_state.reset()

    # --- closing ---------------------------------------------------------------------------
    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 - Qt's name
        if not self.tabs.close_functions() or not self.documents.may_quit():
            event.ignore()
            return
        self.save_layout()
        if self.compiler.worker is not None:  # its thread, and the warm-up's child process
            self.compiler.worker.shutdown()
        event.accept()
