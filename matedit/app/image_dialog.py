"""File › Save Viewport Image's options: the image's size (the view's own, or any other,
drawn offscreen) and its format (PNG as shown, or linear EXR), before the file dialog."""

from __future__ import annotations

from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSpinBox,
    QWidget,
)

MAX_SIDE = 8192  # texels: an offscreen target llvmpipe and GPUs allocate alike
FORMATS = {"png": "PNG, as shown (8-bit sRGB)", "exr": "OpenEXR, linear radiance"}


class ImageSizeDialog(QDialog):
    """Width, height (the view's size to begin with) and format."""

    def __init__(self, view_size: tuple[int, int], parent=None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Save Viewport Image")
        self.view_size = view_size
        form = QFormLayout(self)
        self.width_box, self.height_box = QSpinBox(), QSpinBox()
        for box, value in ((self.width_box, view_size[0]), (self.height_box, view_size[1])):
            box.setRange(16, MAX_SIDE)
            box.setSuffix(" px")
            box.setValue(value)
        row = QWidget()
        rl = QHBoxLayout(row)
        rl.setContentsMargins(0, 0, 0, 0)
        rl.addWidget(self.width_box)
        rl.addWidget(QLabel("×"))
        rl.addWidget(self.height_box)
        same = QPushButton("View size")
        same.setToolTip(f"The view's own size, {view_size[0]} × {view_size[1]}")
        same.clicked.connect(self.use_view_size)
        rl.addWidget(same)
        form.addRow("Size", row)
        self.format_box = QComboBox()
        for key, text in FORMATS.items():
            self.format_box.addItem(text, key)
        form.addRow("Format", self.format_box)
        note = QLabel("Another size than the view's is drawn offscreen; reference mode "
                      "converges first.")
        note.setWordWrap(True)
        note.setObjectName("fieldLabel")
        form.addRow(note)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Save |
                                   QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def use_view_size(self) -> None:
        self.width_box.setValue(self.view_size[0])
        self.height_box.setValue(self.view_size[1])

    def chosen(self) -> tuple[tuple[int, int], str]:
        """((width, height), "png" | "exr")."""
        return (self.width_box.value(), self.height_box.value()), self.format_box.currentData()
