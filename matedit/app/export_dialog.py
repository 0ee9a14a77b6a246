"""Export compiled shaders: targets and a folder; the same files as `matedit compile`
(STEM.TARGET.vert and .frag, STEM.vert.hlsl, STEM.frag.metal and the rest, and
STEM.reflection.json), never over the material or a file it uses.

Every target `matedit compile --target` knows is offered: the GLSL dialects, and HLSL and MSL
(translated from glsl450 through SPIR-V by spirv-cross). Where a tool HLSL/MSL need is not
installed, their boxes are greyed and the tooltip names the Debian package to install."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QSettings
from PySide6.QtWidgets import (
    QCheckBox,
    QDialog,
    QDialogButtonBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QMessageBox,
    QPushButton,
    QVBoxLayout,
)

from matedit.app import file_dialogs
from matedit.compiler import TARGETS, CompileError
from matedit.compiler.targets import CROSS_TARGETS
from matedit.graph.model import MaterialDocument
from matedit.interop.export import export_shaders
from matedit.io.document import FileResolver
from matedit.io.inputs import OverwriteError

FOLDER_KEY = "export/folder"
TARGETS_KEY = "export/targets"
LABELS = {"hlsl": "hlsl (shader model 5.0)", "msl": "msl (Metal 2.0)"}


def missing_packages() -> list[tuple[str, str]]:
    """(tool, Debian package) for each tool HLSL/MSL need that is not on PATH."""
    import shutil

    from matedit.interop.cross import TOOLS

    return [(t, pkg) for t, pkg in TOOLS.items() if not shutil.which(t)]


class ExportDialog(QDialog):
    def __init__(self, doc: MaterialDocument, resolver: FileResolver | None, parent=None):
        super().__init__(parent)
        self.setWindowTitle("Export shaders")
        self.doc, self.resolver = doc, resolver
        self.written: list[Path] = []
        lay = QVBoxLayout(self)
        lay.addWidget(QLabel("Targets"))
        self.boxes = {}
        remembered = QSettings().value(TARGETS_KEY, ["glsl330"])
        remembered = [remembered] if isinstance(remembered, str) else list(remembered or [])
        missing = missing_packages()
        for t in [*TARGETS, *CROSS_TARGETS]:
            box = QCheckBox(LABELS.get(t, t))
            if t in CROSS_TARGETS:
                if missing:
                    box.setEnabled(False)
                    box.setToolTip(f"{t.upper()} needs " + ", ".join(
                        f"{tool} (Debian package {pkg}: apt-get install {pkg})"
                        for tool, pkg in missing))
                else:
                    box.setToolTip(f"{t.upper()} translated from glsl450 through SPIR-V "
                                   "(glslangValidator, spirv-cross)")
            box.setChecked(t in remembered and box.isEnabled())
            box.toggled.connect(self._remember_targets)
            lay.addWidget(box)
            self.boxes[t] = box
        lay.addWidget(QLabel("Folder"))
        row = QHBoxLayout()
        default = QSettings().value(FOLDER_KEY, "") or (
            str(Path(doc.path).parent / "shaders") if doc.path else "")
        self.folder = QLineEdit(str(default))
        browse = QPushButton("Browse…")
        browse.clicked.connect(self._browse)
        row.addWidget(self.folder, 1)
        row.addWidget(browse)
        lay.addLayout(row)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Cancel)
        buttons.addButton("Export", QDialogButtonBox.ButtonRole.AcceptRole)
        buttons.accepted.connect(self.run_export)
        buttons.rejected.connect(self.reject)
        lay.addWidget(buttons)
        self.resize(420, self.sizeHint().height())

    def _remember_targets(self, _on: bool = False) -> None:
        """The targets chosen are the next export's default (across restarts)."""
        QSettings().setValue(TARGETS_KEY, self.targets())

    def targets(self) -> list[str]:
        return [t for t, b in self.boxes.items() if b.isChecked() and b.isEnabled()]

    def _browse(self) -> None:
        folder = file_dialogs.existing_folder(self, "Export into", self.folder.text())
        if folder:
            self.folder.setText(folder)

    def run_export(self) -> bool:
        targets = self.targets()
        folder = self.folder.text().strip()
        if not targets or not folder:
            QMessageBox.warning(self, "Export shaders", "Choose at least one target and a folder.")
            return False
        from matedit.interop.cross import CrossCompileError

        try:
            self.written = export_shaders(self.doc, self.resolver, targets, Path(folder))
        except CrossCompileError as exc:
            QMessageBox.critical(self, "Export shaders", f"Nothing was written: {exc}")
            return False
        except CompileError as exc:
            QMessageBox.critical(self, "Export shaders", "The material does not compile:\n"
                                 + "\n".join(d.format() for d in exc.diagnostics[:10]))
            return False
        except OverwriteError as exc:
            QMessageBox.critical(self, "Export shaders", f"Nothing was written: {exc}")
            return False
        except OSError as exc:
            QMessageBox.critical(self, "Export shaders", f"Cannot write to {folder}:\n{exc}")
            return False
        QSettings().setValue(FOLDER_KEY, folder)
        self.accept()
        return True
