"""The problems model: one place that merges what is wrong with the open documents.

Validation (per tab, from its controller's analysis), the compiler and the GL
driver each report; the model keeps the compiler's and the driver's latest word,
merges them with a tab's validation without duplicates (validation and the
compiler often say the same thing), and says what the status bar should show.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, Signal

from matedit.app.diagnostics import Problem

if TYPE_CHECKING:
    from matedit.app.compile_service import MaterialCompiler
    from matedit.app.viewport_panel import ViewportPanel


def unique(problems: list[Problem]) -> list[Problem]:
    seen: set[tuple] = set()
    out = []
    for p in problems:
        key = (p.severity, p.message, p.node_id, p.field)
        if key not in seen:
            seen.add(key)
            out.append(p)
    return out


class ProblemsModel(QObject):
    """Follows a `MaterialCompiler` and a viewport widget; `changed` after each report."""

    changed = Signal()

    def __init__(self, compiler: MaterialCompiler, view: ViewportPanel, parent=None) -> None:
        super().__init__(parent)
        self.compiler = compiler
        self.compile: list[Problem] = []
        self.gl: list[Problem] = []
        self.budget: list[Problem] = []  # the cost budget's warnings (matedit.app.stats_dock)
        self.imported: list[Problem] = []  # the open material's import warnings
        self.exported: list[Problem] = []  # the last File › Export's warning:/note: lines
        self.status = ""
        self.view = view
        compiler.compiled.connect(self._compiled)
        compiler.failed.connect(self._failed)
        compiler.documentChanged.connect(self._document_changed)
        view.glErrors.connect(self._gl_errors)
        view.materialApplied.connect(self._applied)

    def _compiled(self, _cm) -> None:
        self.compile = []
        self.status = f"compiled in {self.compiler.last_compile_ms:.0f} ms"
        self.changed.emit()

    def _document_changed(self) -> None:
        """Another document: the previous one's compiler, driver, budget and import reports
        are not its."""
        self.compile, self.gl, self.budget, self.imported, self.status = [], [], [], [], ""
        self.exported = []
        self.changed.emit()

    def set_import_warnings(self, messages: list[str]) -> None:
        """What the import that made the open material did not represent exactly (File ›
        Import MaterialX's `warning:` lines): Diagnostics lists them until another document
        is opened."""
        self.imported = [Problem("warning", m, "", "", "import") for m in messages]
        self.changed.emit()

    def set_export_report(self, lines: list[str]) -> None:
        """The last File › Export's `warning:`, `note:` and `error:` lines, as `matedit
        export` prints them (the round trip's ΔE among the notes): Diagnostics lists them
        until the next export or another document."""
        out = []
        for line in lines:
            severity, _, text = line.partition(": ")
            out.append(Problem(severity if severity in ("error", "warning") else "note", text,
                               "", "", "export"))
        self.exported = out
        self.changed.emit()

    def _shows_material(self) -> bool:
        return self.view.shows_material()

    def _failed(self, diagnostics) -> None:
        self.compile = [Problem(d.severity.value, d.message, d.node_id or "", d.port or "",
                                "compiler") for d in diagnostics]
        if self.compiler.latest is not None:
            self.status = "does not compile: the viewport shows this material's last good version"
        else:
            self.status = "does not compile: nothing to show in the viewport (see Diagnostics)"
        self.changed.emit()

    def _gl_errors(self, errors) -> None:
        self.gl = [Problem("error", str(msg), nid or "", "", "GL") for nid, msg in errors]
        if self._shows_material():
            self.status = "GLSL failed to build: the viewport keeps this material's last good " \
                "program"
        else:
            self.status = "GLSL failed to build: nothing to show in the viewport"
        self.changed.emit()

    def _applied(self, ok: bool) -> None:
        if ok and self.gl:
            self.gl = []
            self.changed.emit()

    def for_tab(self, analysis, is_material: bool) -> list[Problem]:
        """A tab's problems: its validation, and for the material the compiler's and GL's."""
        out = [Problem(d.severity.value, d.message, d.node_id or "", d.port or "", "graph")
               for d in (analysis.diagnostics if analysis is not None else [])]
        if is_material:
            out += self.compile + self.gl + self.budget + self.imported + self.exported
        return unique(out)

    def set_budget(self, problems: list[Problem]) -> None:
        if problems != self.budget:
            self.budget = list(problems)
            self.changed.emit()

    @property
    def material_fails(self) -> bool:
        """Whether the material's last compile or GL build failed (what the status says)."""
        return any(p.severity == "error" for p in self.compile + self.gl)

    def empty_text(self, is_material: bool) -> str:
        """The Diagnostics panel's line when a tab has no problems of its own: a function
        tab says so of itself, and that the material still does not compile where it
        does not (its tab lists why)."""
        if is_material:
            return "No problems: the material compiles."
        if self.material_fails:
            return "No problems in this function; the material does not compile (see its tab)."
        return "No problems in this function."

    def material_errors(self) -> dict[str, str]:
        """The compiler's and GL's errors by node (badges on the material's canvas)."""
        out: dict[str, str] = {}
        for p in self.compile + self.gl:
            if p.node_id and p.severity == "error":
                out[p.node_id] = p.message
        return out
