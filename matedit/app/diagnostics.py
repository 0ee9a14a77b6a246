"""The diagnostics list: validation, compile and GL errors with their node and field.

Clicking a row asks the canvas to select its node.
"""

from __future__ import annotations

from dataclasses import dataclass

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import QTreeWidget, QTreeWidgetItem

from matedit.app.theme import icon

NODE_ROLE = Qt.ItemDataRole.UserRole


@dataclass(frozen=True)
class Problem:
    severity: str  # "error" | "warning" | "note" (an export's notes)
    message: str
    node_id: str = ""
    field: str = ""
    source: str = ""  # "graph" | "compiler" | "GL"


class DiagnosticsPanel(QTreeWidget):
    nodeActivated = Signal(str)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setColumnCount(4)
        self.setHeaderLabels(["", "node", "field", "message"])
        self.setRootIsDecorated(False)
        self.setAlternatingRowColors(True)
        self.setUniformRowHeights(True)
        self.setColumnWidth(0, 28)
        self.setColumnWidth(1, 110)
        self.setColumnWidth(2, 110)
        self.problems: list[Problem] = []
        self.itemClicked.connect(self._clicked)
        self.itemActivated.connect(self._clicked)
        self.set_problems([])

    def set_problems(self, problems: list[Problem],
                     empty_text: str = "No problems: the material compiles.") -> None:
        """The rows; `empty_text` is the one row shown when there are none."""
        seen = set()
        unique = []
        for p in problems:  # validation and the compiler often report the same thing
            key = (p.severity, p.message, p.node_id, p.field)
            if key not in seen:
                seen.add(key)
                unique.append(p)
        self.problems = unique
        self.clear()
        if not unique:
            it = QTreeWidgetItem(self, ["", "", "", empty_text])
            it.setIcon(0, icon("ok"))
            return
        order = {"error": 0, "warning": 1}
        for p in sorted(unique, key=lambda p: (order.get(p.severity, 2), p.node_id)):
            it = QTreeWidgetItem(self, ["", p.node_id, p.field, p.message])
            it.setIcon(0, icon({"error": "error", "note": "export"}.get(p.severity, "warning")))
            it.setToolTip(3, f"{p.source}: {p.message}" if p.source else p.message)
            it.setData(0, NODE_ROLE, p.node_id)

    def errors_by_node(self) -> dict[str, str]:
        out: dict[str, str] = {}
        for p in self.problems:
            if p.node_id and p.severity == "error":
                out[p.node_id] = (out[p.node_id] + "\n" if p.node_id in out else "") + p.message
        return out

    def _clicked(self, item: QTreeWidgetItem, _col: int = 0) -> None:
        nid = item.data(0, NODE_ROLE)
        if nid:
            self.nodeActivated.emit(nid)
