"""The Stats dock (View ▸ Stats), the Layers panel's cost column and the cost budget's warnings
in Diagnostics (issue 28).

The figures are `matedit stats`'s (`matedit.interop.stats`), computed by `StatsService`, the
canvas cost overlay's worker (`CostOverlay`: a copy of the document on a worker thread, one
computation at a time, edits in a burst coalesced) asked for every target and the static
switches' permutations. The service runs while the dock is shown and follows structural edits;
the UI thread only lays out the answer. The Layers panel's column takes the layers' figures from
whichever report came last, the dock's or the material canvas's overlay (both glsl450). The
budget (QSettings `stats/budgetSamplers`, `stats/budgetInstructions`, set in the dock) is
checked on each report of the dock.
"""

from __future__ import annotations

from dataclasses import dataclass

from PySide6.QtCore import QSettings, Qt
from PySide6.QtWidgets import (
    QDockWidget,
    QFormLayout,
    QLabel,
    QMainWindow,
    QSpinBox,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from matedit.app.canvas.cost_overlay import CostOverlay
from matedit.app.diagnostics import Problem
from matedit.interop.stats import ALL_TARGETS, DEFAULT_BUDGET, over_budget

SAMPLERS_KEY = "stats/budgetSamplers"
INSTRUCTIONS_KEY = "stats/budgetInstructions"
COLUMNS = ("target", "instructions", "static", "ALU", "texture", "memory", "control",
           "samples", "samplers", "uniform bytes", "varyings")
_FIELDS = ("instructions", None, "alu", "texture", "memory", "control", "samples", "samplers",
           "uniform_bytes", "varyings")


def budget() -> tuple[int, int]:
    """(samplers on essl300, dynamic glsl450 instructions) the material should stay within."""
    s = QSettings()

    def read(key: str, default: int) -> int:
        try:
            v = int(s.value(key, default))
        except (TypeError, ValueError):
            return default
        return v if v > 0 else default

    return (read(SAMPLERS_KEY, DEFAULT_BUDGET["samplers"]),
            read(INSTRUCTIONS_KEY, DEFAULT_BUDGET["instructions"]))


def budget_problems(report: dict) -> list[Problem]:
    """The Diagnostics rows of a report of `StatsService` that passes the budget."""
    samplers, instructions = budget()
    return [Problem("warning", f"cost budget: {text}", "", "", "stats")
            for text in over_budget(report["targets"], samplers, instructions)]


def layer_costs(report: dict) -> dict[str, tuple[float, float]]:
    """layer id -> (instructions, share of the material's) from one target's figures."""
    total = report.get("instructions") or 1
    return {lay["id"]: (lay["instructions"], lay["instructions"] / total)
            for lay in report.get("layers", [])}


class StatsService(CostOverlay):
    """The overlay's worker asked for every target and the permutations: `report` is
    glsl450's figures with `targets` (all of them) and `permutations` added."""

    @staticmethod
    def compute(doc) -> dict:
        from matedit.interop.stats import material_stats, permutations
        from matedit.io.document import FileResolver

        resolver = FileResolver()
        per_target = material_stats(doc, resolver, list(ALL_TARGETS))
        return {**per_target["glsl450"], "targets": per_target,
                "permutations": permutations(doc, resolver)}


class StatsPanel(QWidget):
    """Per-target totals, the permutations and the budget."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setObjectName("statsPanel")
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        self.status = QLabel("Shown while this panel is open: the figures of `matedit stats`, "
                             "computed in the background.")
        self.status.setWordWrap(True)
        self.status.setObjectName("fieldLabel")
        lay.addWidget(self.status)
        self.totals = QTreeWidget()
        self.totals.setObjectName("statsTotals")
        self.totals.setColumnCount(len(COLUMNS))
        self.totals.setHeaderLabels(list(COLUMNS))
        self.totals.setRootIsDecorated(False)
        self.totals.setUniformRowHeights(True)
        self.totals.setToolTip("Instructions of the optimised fragment shader (spirv-opt -O), "
                               "dynamic: loops by their trip counts with the current values; "
                               "'static' counts each instruction once. HLSL and MSL are the "
                               "glsl450 module translated by spirv-cross.")
        lay.addWidget(self.totals, 2)
        self.perms = QTreeWidget()
        self.perms.setObjectName("statsPermutations")
        self.perms.setColumnCount(4)
        self.perms.setHeaderLabels(["permutation", "instructions", "samples", ""])
        self.perms.setRootIsDecorated(False)
        lay.addWidget(self.perms, 1)
        form = QFormLayout()
        samplers, instructions = budget()
        self.budget_samplers = QSpinBox()
        self.budget_samplers.setRange(1, 256)
        self.budget_samplers.setValue(samplers)
        self.budget_samplers.setToolTip("Diagnostics warns above this many texture samplers "
                                        "on essl300 (WebGL2 guarantees 16)")
        self.budget_instructions = QSpinBox()
        self.budget_instructions.setRange(100, 10_000_000)
        self.budget_instructions.setSingleStep(1000)
        self.budget_instructions.setValue(instructions)
        self.budget_instructions.setToolTip("Diagnostics warns above this many dynamic "
                                            "instructions on glsl450")
        form.addRow("budget: samplers (essl300)", self.budget_samplers)
        form.addRow("budget: instructions (glsl450)", self.budget_instructions)
        lay.addLayout(form)
        self.budget_samplers.valueChanged.connect(
            lambda v: QSettings().setValue(SAMPLERS_KEY, int(v)))
        self.budget_instructions.valueChanged.connect(
            lambda v: QSettings().setValue(INSTRUCTIONS_KEY, int(v)))
        self.report: dict | None = None

    def computing(self) -> None:
        self.status.setText("computing…")

    def failed(self, text: str) -> None:
        self.status.setText(text)

    def show_report(self, report: dict) -> None:
        self.report = report
        self.totals.clear()
        for t, f in report["targets"].items():
            cells = [t]
            for k in _FIELDS:
                cells.append(str(f["static"]["instructions"] if k is None else f[k]))
            it = QTreeWidgetItem(self.totals, cells)
            it.setToolTip(0, f["module"])
            for c in range(1, len(COLUMNS)):
                it.setTextAlignment(c, Qt.AlignmentFlag.AlignRight)
        for c in range(len(COLUMNS)):
            self.totals.resizeColumnToContents(c)
        self.perms.clear()
        p = report["permutations"]
        if not p["switches"]:
            QTreeWidgetItem(self.perms, ["no static switches: one permutation", "", "", ""])
        for v in p["variants"]:
            name = ", ".join(f"{k}={'on' if b else 'off'}" for k, b in v["values"].items())
            QTreeWidgetItem(self.perms, [name, str(v["instructions"]), str(v["samples"]),
                                         "current" if v["current"] else ""])
        self.perms.resizeColumnToContents(0)
        g = report["targets"].get("glsl450", report)
        self.status.setText(f"{len(report['targets'])} targets; glsl450: "
                            f"{g['instructions']} instructions, {g['samplers']} samplers; "
                            f"{p['count']} permutation{'s' if p['count'] != 1 else ''}")


@dataclass
class Stats:
    dock: QDockWidget
    panel: StatsPanel
    service: StatsService


def install_stats(window: QMainWindow, controller, layers, problems, overlay: CostOverlay,
                  below: QDockWidget) -> Stats:
    """The Stats dock, tabbed with `below` (not raised), its service following `controller`;
    the Layers panel's costs from its reports and `overlay`'s; its budget into `problems`."""
    from matedit.app.docks import add_dock

    panel = StatsPanel()
    service = StatsService(window, lambda: controller.document)
    dock = add_dock(window, "Stats", "statsDock", panel, Qt.DockWidgetArea.BottomDockWidgetArea)
    window.tabifyDockWidget(below, dock)
    below.raise_()

    def visible(on: bool) -> None:
        if on != service.active:
            service.set_active(on)
            if on:
                panel.computing()

    dock.visibilityChanged.connect(visible)
    # every edit: a value (an octave count) changes the dynamic figures too
    controller.changed.connect(lambda _ev: service.document_changed())
    controller.documentReplaced.connect(service.document_changed)
    service.computed.connect(panel.show_report)
    service.computed.connect(lambda r: layers.set_costs(layer_costs(r)))
    service.computed.connect(lambda r: problems.set_budget(budget_problems(r)))
    service.failed.connect(panel.failed)
    overlay.computed.connect(lambda r: layers.set_costs(layer_costs(r)))
    return Stats(dock, panel, service)
