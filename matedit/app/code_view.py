"""Read-only view of the generated GLSL for one target, refreshed after every recompile (on
the next turn of the event loop) while it is shown; hidden (its dock closed or behind another
tab), it refreshes when it shows again: setting a few thousand lines of text costs 30-50 ms of
the UI thread, which every structural edit would otherwise pay for a panel nobody looks at."""

from __future__ import annotations

from PySide6.QtGui import QFont, QFontDatabase, QTextOption
from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QPlainTextEdit, QVBoxLayout, QWidget

from matedit.app.compile_service import MaterialCompiler
from matedit.app.turns import turns
from matedit.compiler import TARGETS, CompileError

STAGES = ("fragment", "vertex")


class CodeView(QWidget):
    def __init__(self, compiler: MaterialCompiler, parent=None) -> None:
        super().__init__(parent)
        self.compiler = compiler
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.setSpacing(4)
        bar = QHBoxLayout()
        self.target = QComboBox()
        self.target.addItems(list(TARGETS))
        self.target.setToolTip("GLSL dialect")
        self.stage = QComboBox()
        self.stage.addItems(list(STAGES))
        self.info = QLabel("")
        self.info.setObjectName("fieldLabel")
        bar.addWidget(self.target)
        bar.addWidget(self.stage)
        bar.addWidget(self.info, 1)
        lay.addLayout(bar)
        self.text = QPlainTextEdit()
        self.text.setObjectName("codeView")
        self.text.setReadOnly(True)
        self.text.setWordWrapMode(QTextOption.WrapMode.NoWrap)
        font = QFontDatabase.systemFont(QFontDatabase.SystemFont.FixedFont)
        font.setStyleHint(QFont.StyleHint.Monospace)
        self.text.setFont(font)
        lay.addWidget(self.text, 1)
        self.target.currentTextChanged.connect(self.refresh)
        self.stage.currentTextChanged.connect(self.refresh)
        compiler.compiled.connect(lambda _cm: self._changed())
        compiler.failed.connect(lambda _d: self._changed())
        self._stale = False
        self.refresh()

    def _changed(self) -> None:
        # shown: refreshed on its own turn of the event loop, not inside the compile's
        # delivery (setting the text costs 7-10 ms, added to whatever else that event does)
        self._stale = True
        if self.isVisible():
            turns().add(self, "refresh", self.ensure_current)

    def showEvent(self, event) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        self.ensure_current()

    def ensure_current(self) -> None:
        """Shows the latest compile's code now, if the panel has missed one while hidden."""
        if self._stale:
            self.refresh()

    def refresh(self) -> None:
        self._stale = False
        if self.compiler.controller.document.is_function:
            self._show("// a material function compiles as part of the materials that call it",
                       "")
            return
        if self.compiler.current is None:
            last = self.compiler.last_good  # this document's own: see MaterialCompiler
            if last is not None and self.target.currentText() == last.target:
                self._show(self._stage_text(last),
                           "does not compile; showing this material's last good code")
            elif last is not None:
                self._show("// the material does not compile: see Diagnostics",
                           "does not compile")
            else:
                self._show(self._never_compiled(), "does not compile: no code to show")
            return
        try:
            cm = self.compiler.for_target(self.target.currentText())
        except CompileError as exc:
            self._show("// " + "\n// ".join(d.format() for d in exc.diagnostics), "error")
            return
        self._show(self._stage_text(cm), f"{len(cm.fragment_text.splitlines())} fragment lines"
                   f"  ·  hash {cm.structure_hash}")

    def _never_compiled(self) -> str:
        """What the panel says for a document that has not compiled yet: its errors."""
        errors = [d.format() for d in self.compiler.diagnostics if d.severity.value == "error"]
        lines = ["// This material does not compile, and it has not compiled since it was",
                 "// opened: there is no GLSL to show. Fix the errors listed in Diagnostics:"]
        lines += [f"//   {e}" for e in errors[:20]]
        if len(errors) > 20:
            lines.append(f"//   … and {len(errors) - 20} more")
        return "\n".join(lines)

    def _stage_text(self, cm) -> str:
        return cm.fragment_text if self.stage.currentText() == "fragment" else cm.vertex_text

    def _show(self, text: str, info: str) -> None:
        if self.text.toPlainText() != text:
            bar = self.text.verticalScrollBar()
            pos = bar.value()
            self.text.setPlainText(text)
            bar.setValue(pos)
        self.info.setText(info)
