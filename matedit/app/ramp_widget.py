"""The Colour Ramp node's stops editor: a gradient bar with draggable stop handles.

The bar is the node's own numpy twin evaluated across [0, 1], so it shows exactly what the
shader computes. Click a handle to select it, drag it to move it (between its neighbours,
so stops stay sorted), double-click the bar to add a stop there, Delete (or the button)
removes the selected one, and the swatch sets its colour. Every edit is SetValue commands
on the node's `stops`, `position<k>` and `color<k>` inputs (value edits: no recompile); a
drag is one undo step.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QImage, QPainter, QPen, QPolygonF
from PySide6.QtWidgets import QHBoxLayout, QLabel, QPushButton, QVBoxLayout, QWidget

from matedit.app.controller import DocumentController, new_merge_id
from matedit.app.fields import ColorField
from matedit.graph import nodes
from matedit.graph.commands import SetValue
from matedit.graph.nodes import RAMP_STOPS

_BAR_H = 22
_HANDLE = 7
_MARGIN = 8


def _encode(c: float) -> int:
    c = min(max(c, 0.0), 1.0)
    s = 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055
    return int(round(s * 255))


class RampStops:
    """The ramp's stops as the node holds them (values, else the catalogue's defaults)."""

    def __init__(self, values: dict) -> None:
        d = nodes.definition(nodes.kind_for(nodes.Role.COLOR_RAMP))
        get = {i.name: values.get(i.name, i.default) for i in d.inputs}
        self.count = int(min(max(float(get["stops"]), 2), RAMP_STOPS))
        self.positions = [float(get[f"position{k}"]) for k in range(RAMP_STOPS)]
        self.colors = [[float(x) for x in get[f"color{k}"]] for k in range(RAMP_STOPS)]

    def evaluate(self, t: np.ndarray) -> np.ndarray:
        """The ramp at values t, by the node's numpy twin."""
        n = len(t)
        col = [np.full(n, p) for p in self.positions]
        colors = [np.tile(c, (n, 1)) for c in self.colors]
        ramp = nodes.definition(nodes.kind_for(nodes.Role.COLOR_RAMP)).numpy
        assert ramp is not None
        (out,) = ramp(None, t, np.full(n, float(self.count)), *col, *colors)
        return out

    def values(self) -> dict:
        out: dict = {"stops": float(self.count)}
        for k in range(RAMP_STOPS):
            out[f"position{k}"] = round(self.positions[k], 6)
            out[f"color{k}"] = [round(x, 6) for x in self.colors[k]]
        return out

    def insert(self, position: float) -> int:
        """Adds a stop at `position` with the ramp's colour there; its index (stops stay
        sorted: the ones above shift up)."""
        if self.count >= RAMP_STOPS:
            raise ValueError(f"a ramp has at most {RAMP_STOPS} stops")
        color = [float(x) for x in self.evaluate(np.array([position]))[0]]
        k = sum(1 for p in self.positions[:self.count] if p <= position)
        self.positions.insert(k, position)
        self.colors.insert(k, color)
        self.positions.pop()
        self.colors.pop()
        self.count += 1
        return k

    def remove(self, k: int) -> None:
        if self.count <= 2:
            raise ValueError("a ramp needs two stops")
        last_p, last_c = self.positions[self.count - 1], self.colors[self.count - 1]
        del self.positions[k]
        del self.colors[k]
        self.positions.append(last_p)  # unused slots repeat the last stop
        self.colors.append(list(last_c))
        self.count -= 1

    def move(self, k: int, position: float) -> float:
        lo = self.positions[k - 1] if k > 0 else 0.0
        hi = self.positions[k + 1] if k + 1 < self.count else 1.0
        self.positions[k] = min(max(position, lo), hi, 1.0)
        return self.positions[k]


class RampBar(QWidget):
    """The gradient with its handles."""

    selected = Signal(int)
    moved = Signal(int, float, object)  # stop, position, merge id
    added = Signal(float)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.stops: RampStops | None = None
        self.current = 0
        self._drag: int | None = None
        self._merge = None
        self.setMinimumHeight(_BAR_H + 2 * _HANDLE + 6)
        self.setMouseTracking(False)
        self.setToolTip("Drag a stop to move it; double-click to add one")

    def _span(self) -> tuple[float, float]:
        return _MARGIN, max(self.width() - 2 * _MARGIN, 1)

    def x_of(self, position: float) -> float:
        x0, w = self._span()
        return x0 + position * w

    def position_at(self, x: float) -> float:
        x0, w = self._span()
        return min(max((x - x0) / w, 0.0), 1.0)

    def handle_at(self, x: float) -> int | None:
        if self.stops is None:
            return None
        best, dist = None, _HANDLE + 2.0
        for k in range(self.stops.count):
            d = abs(self.x_of(self.stops.positions[k]) - x)
            if d <= dist:
                best, dist = k, d
        return best

    def paintEvent(self, _event) -> None:
        if self.stops is None:
            return
        p = QPainter(self)
        x0, w = self._span()
        n = max(int(w), 2)
        rgb = self.stops.evaluate((np.arange(n) + 0.5) / n)
        img = QImage(n, 1, QImage.Format.Format_RGB32)
        for i, c in enumerate(rgb):
            img.setPixelColor(i, 0, QColor(*(_encode(float(x)) for x in c)))
        p.drawImage(QRectF(x0, 2, w, _BAR_H), img)
        p.setPen(QPen(QColor(20, 20, 24), 1))
        p.drawRect(QRectF(x0, 2, w, _BAR_H))
        for k in range(self.stops.count):
            x = self.x_of(self.stops.positions[k])
            y = 2 + _BAR_H + 1
            tri = QPolygonF([QPointF(x, y), QPointF(x - _HANDLE, y + 2 * _HANDLE),
                             QPointF(x + _HANDLE, y + 2 * _HANDLE)])
            c = self.stops.colors[k]
            p.setBrush(QColor(*(_encode(v) for v in c)))
            p.setPen(QPen(QColor(255, 200, 60) if k == self.current else QColor(200, 200, 200),
                          2 if k == self.current else 1))
            p.drawPolygon(tri)
        p.end()

    def mousePressEvent(self, e) -> None:
        k = self.handle_at(e.position().x())
        if k is not None:
            self.current = k
            self._drag = k
            self._merge = new_merge_id()
            self.selected.emit(k)
            self.update()

    def mouseMoveEvent(self, e) -> None:
        if self._drag is not None:
            self.moved.emit(self._drag, self.position_at(e.position().x()), self._merge)

    def mouseReleaseEvent(self, _e) -> None:
        self._drag = None

    def mouseDoubleClickEvent(self, e) -> None:
        if self.handle_at(e.position().x()) is None:
            self.added.emit(self.position_at(e.position().x()))


class RampEditor(QWidget):
    """The ramp bar, the selected stop's position and colour, and add/remove buttons."""

    def __init__(self, controller: DocumentController, node_id: str, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("rampEditor")
        self.controller = controller
        self.node_id = node_id
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 4, 0, 4)
        self.bar = RampBar()
        lay.addWidget(self.bar)
        row = QHBoxLayout()
        self.label = QLabel()
        self.color = ColorField([0.5, 0.5, 0.5])
        self.add_button = QPushButton("+")
        self.add_button.setToolTip("Add a stop halfway along the widest gap")
        self.remove_button = QPushButton("−")
        self.remove_button.setToolTip("Remove the selected stop")
        row.addWidget(self.label)
        row.addWidget(self.color, 1)
        row.addWidget(self.add_button)
        row.addWidget(self.remove_button)
        lay.addLayout(row)
        self.bar.selected.connect(lambda _k: self._sync())
        self.bar.moved.connect(self._move)
        self.bar.added.connect(self.add_stop)
        self.color.edited.connect(self._recolour)
        self.add_button.clicked.connect(self._add_in_widest_gap)
        self.remove_button.clicked.connect(self.remove_stop)
        controller.valuesChanged.connect(self._values_changed)
        self.refresh()

    def _node(self):
        return self.controller.document.graph.nodes.get(self.node_id)

    def _values_changed(self, change) -> None:
        """Another node's edit leaves the ramp as it is (`change`: a ValueChange)."""
        if change.touches(self.node_id):
            self.refresh()

    def refresh(self) -> None:
        node = self._node()
        if node is None:
            return
        self.bar.stops = RampStops(node.values)
        self.bar.current = min(self.bar.current, self.bar.stops.count - 1)
        self._sync()
        self.bar.update()

    def _sync(self) -> None:
        s = self.bar.stops
        k = self.bar.current
        self.label.setText(f"stop {k}  at {s.positions[k]:.3f}")
        self.color.blockSignals(True)
        self.color.set_value(s.colors[k])
        self.color.blockSignals(False)
        self.remove_button.setEnabled(s.count > 2)
        self.add_button.setEnabled(s.count < RAMP_STOPS)

    def _push(self, stops: RampStops, text: str, only: tuple[str, ...] | None = None,
              merge_id=None) -> None:
        node = self._node()
        cmds = [SetValue(self.node_id, port, v, text=text) for port, v in stops.values().items()
                if (only is None or port in only) and node.values.get(port) != v]
        if not cmds:
            return
        if len(cmds) == 1:
            self.controller.push(cmds[0], merge_id=merge_id)
        else:
            self.controller.push_all(cmds, text)
        self.refresh()

    def _move(self, k: int, position: float, merge_id) -> None:
        s = RampStops(self._node().values)
        s.move(k, position)
        self._push(s, f"move ramp stop {k}", only=(f"position{k}",), merge_id=merge_id)

    def _recolour(self, value, _merge=None) -> None:
        s = RampStops(self._node().values)
        k = self.bar.current
        s.colors[k] = [float(x) for x in value]
        self._push(s, f"colour ramp stop {k}", only=(f"color{k}",))

    def add_stop(self, position: float) -> None:
        s = RampStops(self._node().values)
        if s.count >= RAMP_STOPS:
            return
        self.bar.current = s.insert(position)
        self._push(s, "add ramp stop")

    def _add_in_widest_gap(self) -> None:
        s = RampStops(self._node().values)
        gaps = [(s.positions[k + 1] - s.positions[k], k) for k in range(s.count - 1)]
        _, k = max(gaps)
        self.add_stop(0.5 * (s.positions[k] + s.positions[k + 1]))

    def remove_stop(self) -> None:
        s = RampStops(self._node().values)
        if s.count <= 2:
            return
        s.remove(self.bar.current)
        self.bar.current = max(self.bar.current - 1, 0)
        self._push(s, "remove ramp stop")

    def keyPressEvent(self, e) -> None:
        if e.key() in (Qt.Key.Key_Delete, Qt.Key.Key_Backspace):
            self.remove_stop()
        else:
            super().keyPressEvent(e)
