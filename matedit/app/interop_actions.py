"""File › Export and File › Import entries for the interchange formats: glTF 2.0 (.gltf/.glb),
MaterialX (.mtlx), USD (.usda/.usdz), baked texture maps, and importing a .mtlx, .gltf or .glb.

Each export opens its options dialog (matedit.app.interop_dialog), which runs the command
line's own export (`matedit export`, `matedit bake`) on the document tab in front: a material
as edited, or an instance's resolved material named after the instance, with its outputs
checked against its inputs the same way. Baking needs a GL context: it runs on a worker
thread with its own headless EGL context, so the GUI thread's GLX context is never
disturbed (GLVND refuses GLX on a thread with EGL current).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from PySide6.QtCore import QSettings
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QInputDialog, QMessageBox, QWidget

from matedit.app import file_dialogs

if TYPE_CHECKING:
    from matedit.app.controller import DocumentController
    from matedit.app.document_actions import DocumentActions
    from matedit.app.documents import DocumentTabs
    from matedit.app.interop_dialog import ExportTarget, InteropDialog
    from matedit.app.problems import ProblemsModel

FOLDER_KEY = "interop/folder"


class InteropHost(Protocol):
    """What the interop actions need of the main window."""

    controller: DocumentController
    actions: DocumentActions
    problems: ProblemsModel
    documents: DocumentTabs

    def status(self, text: str) -> None: ...


class InteropActions:
    """The File menu's import and export actions (`entries()`), on `window` (the dialogs'
    parent), working on `host`'s document."""

    def __init__(self, window: QWidget, host: InteropHost) -> None:
        self.window = window  # the dialogs' parent
        self.host = host
        self.last_message = ""
        self.import_report: QMessageBox | None = None  # the last import's warnings, shown
        self.dialog: InteropDialog | None = None  # the last export's dialog
        w = window
        self.act_gltf = QAction("Export &glTF…", w)
        self.act_gltf.triggered.connect(lambda: self.export_gltf())
        self.act_mtlx = QAction("Export &MaterialX…", w)
        self.act_mtlx.triggered.connect(lambda: self.export_mtlx())
        self.act_usd = QAction("Export &USD…", w)
        self.act_usd.triggered.connect(lambda: self.export_usd())
        self.act_bake = QAction("Export &Baked Textures…", w)
        self.act_bake.triggered.connect(lambda: self.export_baked())
        self.act_import = QAction("&Import MaterialX or glTF…", w)
        self.act_import.triggered.connect(lambda: self.import_mtlx())
        self.actions = [self.act_gltf, self.act_mtlx, self.act_usd, self.act_bake]

    def entries(self) -> list[QAction | None]:
        """The File menu's entries, in order (None: a separator)."""
        return [*self.actions, None, self.act_import]

    # --- helpers ---------------------------------------------------------------------------
    @property
    def doc(self):
        return self.host.controller.document

    @property
    def resolver(self):
        return self.host.controller.resolver

    def _stem(self) -> str:
        from matedit.interop.export import stem_of

        return stem_of(self.doc)

    def _start_dir(self) -> str:
        saved = QSettings().value(FOLDER_KEY, "")
        if saved:
            return str(saved)
        return str(Path(self.doc.path).parent) if self.doc.path else ""

    def _fail(self, title: str, exc: Exception) -> bool:
        from matedit.compiler import CompileError

        if isinstance(exc, CompileError):
            text = "The material does not compile:\n" + "\n".join(
                d.format() for d in exc.diagnostics[:10])
        else:
            text = f"Nothing more was written: {exc}"
        QMessageBox.critical(self.window, title, text)
        self.last_message = text
        return False

    def _done(self, text: str) -> bool:
        self.last_message = text
        self.host.status(text)
        return True

    # --- exports -------------------------------------------------------------------------
    def export_target(self) -> ExportTarget:
        """What File › Export works on: the document tab in front, a material as edited or
        an instance's resolved material (named after the instance, as `matedit export`
        reads an instance file; its warnings are the command's `warning:` lines). Raises
        ValueError where there is nothing to export (an instance whose overrides do not
        resolve, a material function)."""
        from matedit.app.compile_worker import snapshot_document
        from matedit.app.interop_dialog import ExportTarget
        from matedit.io.inputs import document_inputs

        session = self.host.documents.current
        editor = session.editor
        if editor is None:
            doc = self.doc
            if doc.is_function:
                raise ValueError("a material function cannot be exported; export a material "
                                 "that calls it")
            source = Path(doc.path) if doc.path else Path(f"{self._stem()}.json")
            return ExportTarget(snapshot_document(doc), self.resolver, source,
                                document_inputs(doc, self.resolver))
        resolved = editor.resolved
        if resolved.errors:
            raise ValueError(resolved.errors[0].format())
        doc = resolved.document
        inputs = document_inputs(doc, editor.resolver)
        for i, p in enumerate(resolved.chain):  # the instance, its parents, the material
            inputs.setdefault(_real(p), "the instance" if i == 0 else "a parent of the "
                              "instance")
        source = Path(editor.doc.path) if editor.doc.path else Path(f"{editor.name()}.json")
        return ExportTarget(snapshot_document(doc), editor.resolver, source, inputs,
                            [w.format() for w in resolved.warnings], instance=True)

    def export_dialog(self, kind: str) -> InteropDialog | None:
        """The options dialog of `kind` (gltf, mtlx, usd, baked) on the tab in front, not
        shown; None (said why) where there is nothing to export."""
        from matedit.app.interop_dialog import KINDS, InteropDialog
        from matedit.interop.export import stem_of

        try:
            target = self.export_target()
        except ValueError as exc:
            text = f"Nothing to export: {exc}"
            self.host.actions.show_error(KINDS[kind].title, text)
            self.last_message = text
            return None
        if self.dialog is not None:
            self.dialog.deleteLater()
        start = str(QSettings().value(FOLDER_KEY, "") or "") or (
            str(target.source.parent) if target.source.is_absolute() else "")
        self.dialog = InteropDialog(kind, target, stem_of(target.doc), start, self._report,
                                    self.window)
        return self.dialog

    def _report(self, lines: list[str]) -> None:
        self.host.problems.set_export_report(lines)

    def export(self, kind: str, out: Path | None = None, size: int | None = None,
               **fields) -> bool:
        """File › Export `kind`: with no `out`, the options dialog for the artist; with one,
        the dialog's export run at once on `out` (`size` and `fields`: surface, format, zip,
        check, set in it first; for scripts and tests)."""
        dlg = self.export_dialog(kind)
        if dlg is None:
            return False
        if out is None:
            dlg.exec()
        else:
            dlg.set_output(out)
            if size is not None:
                dlg.set_size(size)
            for name, value in fields.items():
                widget = getattr(dlg, "map_format" if name == "format" else name)
                if isinstance(value, bool):
                    widget.setChecked(value)
                else:
                    widget.setCurrentIndex(widget.findData(value))
            dlg.run_export()
        text = dlg.result.toPlainText()
        self.last_message = text
        if dlg.ok:
            self.host.status(text.splitlines()[0] if text else "exported")
        return dlg.ok

    def export_gltf(self, out: Path | None = None, size: int | None = None, **fields) -> bool:
        return self.export("gltf", out, size, **fields)

    def export_mtlx(self, out: Path | None = None, size: int | None = None, **fields) -> bool:
        return self.export("mtlx", out, size, **fields)

    def export_usd(self, out: Path | None = None, size: int | None = None, **fields) -> bool:
        return self.export("usd", out, size, **fields)

    def export_baked(self, folder: Path | None = None, size: int | None = None,
                     **fields) -> bool:
        return self.export("baked", folder, size, **fields)

    def _choose_material(self, src: Path, title: str) -> tuple[bool, str | None]:
        """(go on, the material to import): with several in the document, the one picked
        from a list; None when there is only one (or the file cannot be read: the import
        then reports why)."""
        material_names, failure = _reader(src)
        try:
            names = material_names(src)
        except failure:
            return True, None
        if len(names) < 2:
            return True, None
        name, ok = QInputDialog.getItem(self.window, title,
                                        f"{src.name} holds {len(names)} materials; import:",
                                        names, 0, False)
        return bool(ok), (name if ok else None)

    def _import_name(self, src: Path, material: str | None) -> Path:
        """The file proposed for an imported material: its MaterialX name (else the .mtlx's
        stem) as a file stem, made unique in the folder with _2, _3...: never a file that
        exists, so never the open document's."""
        from matedit.interop.mtlx_import import file_stem

        material_names, failure = _reader(src)
        name = material
        if name is None:
            try:
                names = material_names(src)
            except failure:
                names = []
            name = names[0] if len(names) == 1 else None
        stem = file_stem(name) if name else (file_stem(src.stem) or "imported")
        folder = Path(self._start_dir() or src.parent)
        taken = open_document_paths()
        for i in range(1, 1000):
            candidate = folder / (f"{stem}.json" if i == 1 else f"{stem}_{i}.json")
            if not os.path.lexists(candidate) and _real(candidate) not in taken:
                return candidate
        return folder / f"{stem}_{os.getpid()}_{len(taken)}.json"

    def import_mtlx(self, src: Path | None = None, out: Path | None = None,
                    material: str | None = None) -> bool:
        """Import one material of a .mtlx, .gltf or .glb (`material`, else the only one, else
        the one the artist picks), save it (and a glTF's embedded images, beside it) as a new
        file and open it. The name proposed is a new one
        (`_import_name`); a file picked that exists is replaced only after the file dialog's
        own confirmation, and a document open in the editor never is (refused, saying why)."""
        title = "Import MaterialX or glTF"
        if src is None:
            path, _ = file_dialogs.open_file(self.window, title, self._start_dir(),
                                             "MaterialX or glTF (*.mtlx *.gltf *.glb);;"
                                             "MaterialX (*.mtlx);;glTF (*.gltf *.glb)")
            if not path:
                return False
            src = Path(path)
        gltf = _is_gltf(src)
        if material is None:
            go, material = self._choose_material(src, title)
            if not go:
                return False
        if out is None:
            proposed = self._import_name(src, material)
            path, _ = file_dialogs.save_file(self.window, "Save the imported material as",
                                             str(proposed), "Material (*.json)")
            if not path:
                return False
            QSettings().setValue(FOLDER_KEY, str(Path(path).parent))
            out = Path(path)
        out = out.with_suffix(".json")
        if _real(out) in open_document_paths():
            text = (f"{out.name} is open in the editor. An import is saved as a new file and "
                    "never replaces an open document: choose another name.")
            self.host.actions.show_error(title, text)
            self.last_message = text
            return False

        from matedit.interop.gltf_import import GltfImportError, import_gltf
        from matedit.interop.mtlx_import import MtlxImportError, import_mtlx
        from matedit.io.atomic import atomic_write_text, staged_outputs
        from matedit.io.document import dumps
        from matedit.io.inputs import refuse_overwrite

        warnings: list[str] = []
        try:
            inputs = {Path(os.path.realpath(src)): "the glTF asset" if gltf
                      else "the MaterialX document"}
            refuse_overwrite([out], inputs)
            images: dict[Path, bytes] = {}
            if gltf:  # its embedded images are written beside the material, with it
                result = import_gltf(src, out, material, warnings)
                doc, images = result.document, result.images
                inputs.update({_real(p): "a file the glTF asset reads" for p in result.reads})
                refuse_overwrite(list(images), inputs)
            else:
                doc = import_mtlx(src, out, material, warnings)
            _arrange(doc)  # the importer's own columns, made readable
            if not self.host.actions.maybe_save():
                return False
            if images:
                with staged_outputs(out.parent) as stage:
                    for p, data in images.items():
                        stage.write_bytes(p, data)
                    stage.write_text(out, dumps(doc))
            else:
                atomic_write_text(out, dumps(doc))
        except (MtlxImportError, GltfImportError) as exc:
            text = "\n".join(exc.messages[:20])
            QMessageBox.critical(self.window, title, f"Cannot import {src.name}:\n{text}")
            self.last_message = text
            return False
        except Exception as exc:
            return self._fail(title, exc)
        if not self.host.actions.open(out, ask=False):
            return False
        return self._import_warnings(src, warnings) and self._done(f"imported {src.name}")

    def _import_warnings(self, src: Path, warnings: list[str]) -> bool:
        """The import's `warning:` lines, the same as the command line's: in Diagnostics
        (until another document is opened) and, where there are any, a message listing
        them."""
        self.host.problems.set_import_warnings(warnings)
        if self.import_report is not None:
            self.import_report.close()
            self.import_report = None
        if warnings:
            shown = "\n".join(warnings[:20])
            more = f"\n… and {len(warnings) - 20} more (see Diagnostics)" \
                if len(warnings) > 20 else ""
            box = QMessageBox(QMessageBox.Icon.Warning, "Import",
                              f"Imported {src.name}. {len(warnings)} of what it sets "
                              f"{'is' if len(warnings) == 1 else 'are'} not represented "
                              f"exactly (also listed in Diagnostics):\n\n{shown}{more}",
                              QMessageBox.StandardButton.Ok, self.window)
            box.setModal(False)  # the material is open behind it
            box.show()
            self.import_report = box
        return True


def _is_gltf(src: Path) -> bool:
    return src.suffix.lower() in (".gltf", ".glb")


def _reader(src: Path):
    """(material_names, its error type) of the importer for `src`'s format."""
    if _is_gltf(src):
        from matedit.interop import gltf_import

        return gltf_import.material_names, gltf_import.GltfImportError
    from matedit.interop import mtlx_import

    return mtlx_import.material_names, mtlx_import.MtlxImportError


def _arrange(doc) -> None:
    """Arrange every node of `doc` in place (Edit › Arrange over all of it), measured on a
    canvas of its own that is then dropped: an import is laid out before it is saved."""
    from matedit.app.canvas import NodeCanvasView
    from matedit.app.canvas.arrange import arrange
    from matedit.app.controller import DocumentController

    view = NodeCanvasView(DocumentController(doc))
    try:
        scene = view.scene()
        moved, frames, _left = arrange(scene, list(scene.node_items))
    finally:
        view.deleteLater()
    for nid, pos in moved.items():
        doc.graph.nodes[nid].position = pos
    for cid, rect in frames.items():
        doc.graph.comments[cid].rect = rect


def _real(path: Path) -> Path:
    """`path` with every link resolved (as far as it exists), to compare files."""
    return Path(os.path.realpath(path))


def open_document_paths() -> set[Path]:
    """The files of every document open in this editor process (materials and functions, in
    every window and tab), links resolved."""
    import shiboken6

    from matedit.app.document_actions import DocumentActions

    out = set()
    for acts in list(DocumentActions._live):
        if shiboken6.isValid(acts) and acts.document.path is not None:
            out.add(_real(Path(acts.document.path)))
    return out
