"""Export compiled shaders: targets and a folder; the same files as `matedit compile`
(STEM.TARGET.vert, STEM.TARGET.frag and STEM.reflection.json), never over the material or a
file it uses."""

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
from matedit.compiler.export import export_shaders
from matedit.graph.model import MaterialDocument
from matedit.io.document import FileResolver
from matedit.io.inputs import OverwriteError

FOLDER_KEY = "export/folder"
TARGETS_KEY = "export/targets"


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
        for t in TARGETS:
            box = QCheckBox(t)
            box.setChecked(t in remembered)
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
        self.export_button = buttons.addButton("Export", QDialogButtonBox.ButtonRole.AcceptRole)
        buttons.accepted.connect(self.run_export)
        buttons.rejected.connect(self.reject)
        lay.addWidget(buttons)
        self.resize(420, self.sizeHint().height())

    def _remember_targets(self, _on: bool = False) -> None:
        """The targets chosen are the next export's default (across restarts)."""
        QSettings().setValue(TARGETS_KEY, self.targets())

    def targets(self) -> list[str]:
        return [t for t, b in self.boxes.items() if b.isChecked()]

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
        try:
            self.written = export_shaders(self.doc, self.resolver, targets, Path(folder))
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
