"""The options dialog of File › Export glTF, MaterialX, USD and Baked Textures: what
`matedit export` (and `matedit bake`) take, run by the command line's own functions
(`matedit.commands.export.export_document`, `matedit.commands.bake.bake_to_folder`) on the
material of the document tab in front: a material as edited, or an instance's resolved
material named after the instance (as the command line exports an instance file).

Per format: the output (a file, a folder for baked textures) with Browse…, the bake size,
and the command's options: glTF's .glb or .gltf and USD's .usda or .usdz (by the output's
extension), MaterialX's surface shader, map format and zip, USD's Apple profile for a .usdz
(`--arkit`), the baked maps' format, and "Check round trip" (`--check`) where the command
takes it (glTF, USD and MaterialX without zip).
After an export the result area lists what was written, every `note:`/`warning:` line the
command would print and the round trip's ΔE figure; Diagnostics lists them too. The options
are remembered per format (QSettings, `interop/KIND/...`)."""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from PySide6.QtCore import QSettings, Qt
from PySide6.QtWidgets import (
    QApplication,
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QHBoxLayout,
    QLineEdit,
    QPlainTextEdit,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from matedit.app import file_dialogs
from matedit.commands.export import MAP_FORMATS, SURFACES, ExportOptions, default_size
from matedit.render.mesh import BUILTIN_MESHES

SIZES = (256, 512, 1024, 2048, 4096)
OBJ_CHOICE = "OBJ file…"
OBJ_FILTER = "Wavefront OBJ (*.obj)"


@dataclass(frozen=True)
class Kind:
    title: str
    suffixes: tuple[tuple[str, str], ...]  # (extension, what it is); () for a folder
    surface: bool = False  # MaterialX's --surface, --format, --zip
    map_format: bool = False  # baked maps' --format
    check: bool = False  # --check
    arkit: bool = False  # USD's --arkit (a .usdz only)
    mesh: bool = False  # --mesh: the mesh baked on and shipped


KINDS = {
    "gltf": Kind("Export glTF", ((".glb", "glTF binary (.glb: one file)"),
                                 (".gltf", "glTF (.gltf with a .bin and images)")),
                 check=True, mesh=True),
    "mtlx": Kind("Export MaterialX", ((".mtlx", "MaterialX document (.mtlx)"),), surface=True,
                 check=True),
    "usd": Kind("Export USD", ((".usda", "USD text (.usda, textures beside it)"),
                               (".usdz", "USD package (.usdz)")), check=True, arkit=True,
                mesh=True),
    "baked": Kind("Export Baked Textures", (), map_format=True),
}


@dataclass
class ExportTarget:
    """What an export works on: the material (a copy, so that editing while it runs changes
    nothing), the file it is named after (`source`, for messages), the files it must not
    overwrite, and an instance's warnings (the command's `warning:` lines)."""

    doc: object
    resolver: object
    source: Path
    inputs: dict[Path, str]
    warnings: list[str] = field(default_factory=list)
    instance: bool = False


def in_background(fn: Callable[[], object]):
    """Run `fn()` on a worker thread and wait, the GUI kept alive under a busy cursor: the
    export makes its own headless EGL context there, never on the GUI thread (GLVND refuses
    GLX on a thread with EGL current). Its exception is re-raised here."""
    box: dict = {}

    def run() -> None:
        try:
            box["value"] = fn()
        except BaseException as exc:  # handed back to the GUI thread
            box["error"] = exc

    QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
    try:
        t = threading.Thread(target=run, name="matedit-interop", daemon=True)
        t.start()
        while t.is_alive():
            t.join(0.05)
            QApplication.processEvents()
    finally:
        QApplication.restoreOverrideCursor()
    if "error" in box:
        raise box["error"]
    return box.get("value")


def _texels(n: int) -> str:
    return f"{n} × {n} texels"


def _key(kind: str, name: str) -> str:
    return f"interop/{kind}/{name}"


def _combo(items, current, label=str) -> QComboBox:
    box = QComboBox()
    for it in items:
        box.addItem(label(it), it)
    i = box.findData(current)
    box.setCurrentIndex(max(i, 0))
    return box


class InteropDialog(QDialog):
    """One export's options and its result (module docstring). `run_export()` exports with
    the fields as they are (what the Export button does; tests call it)."""

    def __init__(self, kind: str, target: ExportTarget, stem: str, start_dir: str,
                 report: Callable[[list[str]], None] | None = None, parent=None) -> None:
        super().__init__(parent)
        self.kind, self.spec, self.target = kind, KINDS[kind], target
        self.report = report  # the lines, for Diagnostics
        self.lines: list[str] = []  # the last export's result
        self.written: list[Path] = []
        self.ok = False
        self.setWindowTitle(self.spec.title + (" (instance)" if target.instance else ""))
        s = QSettings()
        form = QFormLayout()
        self.path = QLineEdit(self._default_path(s, stem, start_dir))
        self.path.setObjectName("exportPath")
        browse = QPushButton("Browse…")
        browse.clicked.connect(self._browse)
        row = QHBoxLayout()
        row.addWidget(self.path, 1)
        row.addWidget(browse)
        holder = QWidget()
        holder.setLayout(row)
        row.setContentsMargins(0, 0, 0, 0)
        form.addRow("Folder" if not self.spec.suffixes else "File", holder)
        self.file_type: QComboBox | None = None
        self.arkit: QCheckBox | None = None  # made below; the type's choice enables it
        if len(self.spec.suffixes) > 1:
            self.file_type = QComboBox()
            for suffix, what in self.spec.suffixes:
                self.file_type.addItem(what, suffix)
            self._follow_suffix()
            self.file_type.activated.connect(self._suffix_chosen)
            self.path.textEdited.connect(lambda _t: self._follow_suffix())
            form.addRow("Type", self.file_type)
        out = self.output()
        size = int(s.value(_key(kind, "size"), default_size(out) if out.suffix else 1024))
        self.size = _combo(SIZES, size, _texels)
        self.set_size(size)
        self.size.setToolTip("Baked map width and height in texels (--size)")
        form.addRow("Bake size", self.size)
        self.surface = self.map_format = None
        self.zip = self.check = self.mesh = None
        if self.spec.mesh:
            self.mesh = QComboBox()
            self.mesh.addItem("The material's preview mesh", "")
            for name in BUILTIN_MESHES:
                self.mesh.addItem(name.capitalize(), name)
            self.mesh.addItem(OBJ_CHOICE, OBJ_CHOICE)
            kept = str(s.value(_key(kind, "mesh"), "") or "")
            if kept and self.mesh.findData(kept) < 0 and Path(kept).is_file():
                self.mesh.insertItem(self.mesh.count() - 1, Path(kept).name, kept)
            self.mesh.setCurrentIndex(max(0, self.mesh.findData(kept)))
            self._mesh_index = self.mesh.currentIndex()
            self.mesh.activated.connect(self._mesh_chosen)
            self.mesh.setToolTip("The mesh the maps are baked on and the asset carries "
                                 "(--mesh): its positions, normals and tangents shape "
                                 "position- and slope-dependent looks")
            form.addRow("Mesh", self.mesh)
        if self.spec.arkit:
            self.arkit = QCheckBox("Apple's usdz profile (AR Quick Look)")
            self.arkit.setChecked(s.value(_key(kind, "arkit"), False, type=bool))
            self.arkit.setToolTip("A .usdz package only (--arkit): the preview network on PNG "
                                  "maps, without the MaterialX network")
            form.addRow("Profile", self.arkit)
            self._follow_suffix()
        if self.spec.surface:
            self.surface = _combo(SURFACES, s.value(_key(kind, "surface"), SURFACES[0]))
            self.surface.setToolTip("The MaterialX surface shader (--surface)")
            form.addRow("Surface", self.surface)
        if self.spec.surface or self.spec.map_format:
            self.map_format = _combo(MAP_FORMATS, s.value(_key(kind, "format"), "png"))
            self.map_format.setToolTip("Baked maps as 8-bit PNG (sRGB colour, linear data) "
                                       "or float EXR (--format)")
            form.addRow("Map format", self.map_format)
        if self.spec.surface:
            self.zip = QCheckBox("Pack the document and its files into one .zip")
            self.zip.setChecked(s.value(_key(kind, "zip"), False, type=bool))
            form.addRow("Zip", self.zip)
        if self.spec.check:
            self.check = QCheckBox("Check round trip (read back, render both, CIEDE2000 ΔE)")
            self.check.setChecked(s.value(_key(kind, "check"), False, type=bool))
            form.addRow("Check", self.check)
            if self.zip is not None:
                self.zip.toggled.connect(self._zip_toggled)
                self._zip_toggled(self.zip.isChecked())
        self.result = QPlainTextEdit()
        self.result.setObjectName("exportResult")
        self.result.setReadOnly(True)
        self.result.setPlaceholderText("What the export writes and notes appears here.")
        self.result.setMinimumHeight(110)
        lay = QVBoxLayout(self)
        lay.addLayout(form)
        lay.addWidget(self.result, 1)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close)
        self.export_button = buttons.addButton("Export", QDialogButtonBox.ButtonRole.ApplyRole)
        self.export_button.setDefault(True)
        self.export_button.clicked.connect(self.run_export)
        buttons.rejected.connect(self.reject)
        lay.addWidget(buttons)
        self.resize(560, self.sizeHint().height())

    # --- fields ----------------------------------------------------------------------------
    def _default_path(self, s: QSettings, stem: str, start_dir: str) -> str:
        folder = str(s.value(_key(self.kind, "folder"), "") or start_dir)
        if not self.spec.suffixes:
            return folder
        suffix = str(s.value(_key(self.kind, "suffix"), self.spec.suffixes[0][0]))
        if suffix not in dict(self.spec.suffixes):
            suffix = self.spec.suffixes[0][0]
        return str(Path(folder) / f"{stem}{suffix}") if folder else f"{stem}{suffix}"

    def output(self) -> Path:
        return Path(self.path.text().strip())

    def set_output(self, path: str | Path) -> None:
        self.path.setText(str(path))
        self._follow_suffix()

    def set_size(self, n: int) -> None:
        """The bake size (a size off the list is added to it, for scripts and tests)."""
        if self.size.findData(n) < 0:
            self.size.addItem(_texels(n), n)
        self.size.setCurrentIndex(self.size.findData(n))

    def _follow_suffix(self) -> None:
        if self.file_type is not None:
            i = self.file_type.findData(self.output().suffix.lower())
            if i >= 0:
                self.file_type.setCurrentIndex(i)
        if self.arkit is not None:
            self.arkit.setEnabled(self.output().suffix.lower() == ".usdz")

    def _suffix_chosen(self, _i: int) -> None:
        out = self.output()
        if self.file_type is not None and out.name:
            self.path.setText(str(out.with_suffix(self.file_type.currentData())))
            self._follow_suffix()

    def _mesh_chosen(self, index: int) -> None:
        """An OBJ file joins the list (checked first: a file that is no mesh is said in the
        result area, and the choice goes back)."""
        assert self.mesh is not None
        if self.mesh.itemData(index) != OBJ_CHOICE:
            self._mesh_index = index
            return
        from matedit.render.mesh import MeshError, mesh_from_spec

        path, _ = file_dialogs.open_file(self, "Bake on an OBJ mesh", "", OBJ_FILTER)
        if path:
            real = str(Path(path).resolve())
            try:
                mesh_from_spec(real)
            except (MeshError, OSError) as exc:
                self.result.setPlainText(f"{Path(path).name}: not a mesh: {exc}")
                path = ""
            else:
                self.set_mesh(real)
                return
        self.mesh.setCurrentIndex(self._mesh_index)

    def set_mesh(self, spec: str) -> None:
        """The mesh by its --mesh spec ("" for the preview mesh; an OBJ file's path joins
        the list), for scripts and tests."""
        assert self.mesh is not None
        at = self.mesh.findData(spec)
        if at < 0:
            at = self.mesh.count() - 1
            self.mesh.insertItem(at, Path(spec).name, spec)
        self.mesh.setCurrentIndex(at)
        self._mesh_index = at

    def _zip_toggled(self, on: bool) -> None:
        if self.check is not None:
            self.check.setEnabled(not on)
            self.check.setToolTip("A zip leaves no .mtlx to read back: export without zip to "
                                  "check the round trip" if on else "")

    def _browse(self) -> None:
        if not self.spec.suffixes:
            folder = file_dialogs.existing_folder(self, self.spec.title, self.path.text())
            if folder:
                self.path.setText(folder)
            return
        filters = ";;".join(f"{what} (*{suffix})" for suffix, what in self.spec.suffixes)
        path, chosen = file_dialogs.save_file(self, self.spec.title, self.path.text(), filters)
        if path:
            p = Path(path)
            if p.suffix.lower() not in dict(self.spec.suffixes):
                p = p.with_name(p.name + next(
                    (s for s, what in self.spec.suffixes if what in chosen),
                    self.spec.suffixes[0][0]))
            self.set_output(p)

    def options(self) -> ExportOptions:
        """The command's options as the fields stand."""
        zip_on = self.zip is not None and self.zip.isChecked()
        return ExportOptions(
            size=str(self.size.currentData()),
            surface=self.surface.currentData() if self.surface is not None else SURFACES[0],
            format=self.map_format.currentData() if self.map_format is not None else "png",
            zip=zip_on,
            check=self.check is not None and self.check.isChecked() and not zip_on,
            arkit=self.arkit is not None and self.arkit.isEnabled() and self.arkit.isChecked(),
            mesh=(self.mesh.currentData() or None) if self.mesh is not None else None)

    def _remember(self) -> None:
        s = QSettings()
        out = self.output()
        s.setValue(_key(self.kind, "folder"), str(out.parent if self.spec.suffixes else out))
        if self.spec.suffixes:
            s.setValue(_key(self.kind, "suffix"), out.suffix.lower())
        o = self.options()
        s.setValue(_key(self.kind, "size"), int(o.size or 0))
        if self.surface is not None:
            s.setValue(_key(self.kind, "surface"), o.surface)
            s.setValue(_key(self.kind, "zip"), o.zip)
        if self.map_format is not None:
            s.setValue(_key(self.kind, "format"), o.format)
        if self.check is not None:
            s.setValue(_key(self.kind, "check"), self.check.isChecked())
        if self.arkit is not None:
            s.setValue(_key(self.kind, "arkit"), self.arkit.isChecked())
        if self.mesh is not None:
            s.setValue(_key(self.kind, "mesh"), o.mesh or "")

    # --- the export ------------------------------------------------------------------------
    def run_export(self) -> bool:
        """Export with the fields as they are; the result (or the one error line) is shown
        in the result area and given to `report`. True if it was written."""
        from matedit.cli_support import UsageError

        out = self.output()
        warnings = [f"warning: {w}" for w in self.target.warnings]
        notes: list[str] = []
        t = self.target
        say = notes.append  # from the worker thread; read once it is done
        self.ok, self.written = False, []
        try:
            if not out.name:
                raise UsageError("choose where to export to")
            if not self.spec.suffixes:
                from matedit.commands.bake import bake_to_folder

                o = self.options()
                self.written = in_background(lambda: bake_to_folder(
                    t.doc, t.resolver, t.source, out, int(o.size or 0), o.format, t.inputs))
            else:
                from matedit.commands.export import export_document, validate

                if out.suffix.lower() not in dict(self.spec.suffixes):
                    raise UsageError(f"{out.name}: a {self.spec.title[7:]} export ends in "
                                     + " or ".join(s for s, _ in self.spec.suffixes))
                o = self.options()
                validate(o, out)
                done = in_background(lambda: export_document(
                    t.doc, t.resolver, t.source, out, o, t.inputs, say))
                self.written = list(done.files)
        except UsageError as exc:
            self.lines = [*warnings, *(f"note: {n}" for n in notes), f"error: {exc}"]
            return self._show(f"Nothing more was written. error: {exc}")
        except Exception as exc:  # an unforeseen failure: said, never a traceback
            self.lines = [*warnings, f"error: {exc}"]
            return self._show(f"Nothing more was written. error: {exc}")
        self.ok = True
        self._remember()
        self.lines = [*warnings, *(f"note: {n}" for n in notes)]
        self.written.sort(key=lambda p: p != out)  # the export's own file first
        if self.spec.suffixes:
            more = len(self.written) - 1
            names = out.name + (f" and {more} more file{'s' if more > 1 else ''}"
                                if more > 0 else "")
        else:
            names = ", ".join(p.name for p in self.written)
        where = out.parent if self.spec.suffixes else out
        return self._show(f"Exported {names} into {where}")

    def _show(self, head: str) -> bool:
        checked = [ln for ln in self.lines if "round trip:" in ln and "ΔE" in ln]
        body = [head, *checked, *[ln for ln in self.lines if ln not in checked]]
        self.result.setPlainText("\n".join(body))
        if self.report is not None:
            self.report(self.lines)
        return self.ok

    def round_trip_line(self) -> str:
        """The ΔE summary of the last export's check ("" without one)."""
        return next((ln for ln in self.lines if "round trip: mean ΔE" in ln), "")
