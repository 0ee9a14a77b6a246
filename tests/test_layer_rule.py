"""The layer rule: the pure packages import without PySide6 and moderngl."""

from __future__ import annotations

import subprocess
import sys

PURE = ["matedit.graph.types", "matedit.graph.nodes", "matedit.graph.model",
        "matedit.graph.ports", "matedit.graph.commands", "matedit.graph.layers",
        "matedit.graph.validate", "matedit.io.document", "matedit.io.migrations",
        "matedit.glsl.include", "matedit.shading", "matedit.compiler", "matedit.cli",
        "matedit.commands.validate"]

BLOCKER = """
import importlib, importlib.abc, sys
BLOCKED = {blocked!r}
class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in BLOCKED:
            raise ImportError(f'layer rule: {{name}} imported')
sys.meta_path.insert(0, Block())
for mod in {mods!r}:
    importlib.import_module(mod)
"""


def _run(mods, blocked):
    code = BLOCKER.format(blocked=blocked, mods=mods)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)


def test_pure_packages_import_without_qt_or_gl():
    r = _run(PURE, ["PySide6", "shiboken6", "moderngl", "glcontext", "OpenImageIO"])
    assert r.returncode == 0, r.stderr


def test_renderer_side_imports_without_qt():
    mods = ["matedit.ibl", "matedit.render"]
    r = _run(mods, ["PySide6", "shiboken6"])
    assert r.returncode == 0, r.stderr


def test_blocker_really_blocks():
    r = _run(["PySide6.QtCore"], ["PySide6"])
    assert r.returncode != 0 and "layer rule" in r.stderr


def test_only_render_and_app_create_gl_contexts():
    """Nothing above matedit/render creates an OpenGL context (ARCHITECTURE.md, layers)."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[1] / "matedit"
    offenders = [
        str(p.relative_to(root)) for p in root.rglob("*.py")
        if p.relative_to(root).parts[0] not in ("render", "app")
        and ("create_standalone_context" in p.read_text() or "create_context(" in p.read_text())
    ]
    assert offenders == []
