"""The layer rule (matedit/layers.py, docs/architecture.md "Layers and what each may import"):
the pure packages import without PySide6 and moderngl, no layer imports a later one, and no
matedit module takes part in an import cycle."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import networkx as nx

from matedit.layers import LAYERS, Layer, layer_of

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
    """Nothing above matedit/render creates an OpenGL context
    (docs/architecture.md#layers-and-what-each-may-import)."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[1] / "matedit"
    offenders = [
        str(p.relative_to(root)) for p in root.rglob("*.py")
        if p.relative_to(root).parts[0] not in ("render", "app")
        and ("create_standalone_context" in p.read_text() or "create_context(" in p.read_text())
    ]
    assert offenders == []


# ---------------------------------------------------------------------------------------------
# The layer table (matedit/layers.py) and no import cycles, read from the source with `ast`.

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Imp:
    target: str  # a matedit module, or a third-party/standard top-level name
    line: int


def _module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def read_imports(root: Path) -> dict[str, list[Imp]]:
    """Every import of every module of the package at `root`: module level and inside
    functions and classes; the bodies of `if TYPE_CHECKING:` left out. `from P import N` is
    an import of the module P.N when there is one, else of P."""
    sources = {_module_name(p, root): p for p in sorted(root.rglob("*.py"))}
    out: dict[str, list[Imp]] = {}
    for name, path in sources.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        found: list[Imp] = []

        def visit(node: ast.AST, package: str = package, found: list[Imp] = found) -> None:
            if isinstance(node, ast.If) and _is_type_checking(node.test):
                for child in node.orelse:
                    visit(child)
                return
            if isinstance(node, ast.Import):
                found.extend(Imp(a.name, node.lineno) for a in node.names)
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[:len(package.split(".")) - node.level + 1]
                    base = ".".join([*up, *([base] if base else [])])
                for a in node.names:
                    sub = f"{base}.{a.name}"
                    found.append(Imp(sub if sub in sources else base, node.lineno))
            for child in ast.iter_child_nodes(node):
                visit(child)

        visit(ast.parse(path.read_text(), str(path)))
        out[name] = found
    return out


def problems(imports: dict[str, list[Imp]], layers=LAYERS, package: str = "matedit") -> list[str]:
    """Every breach of the layer table and every import cycle among the package's modules."""
    out: list[str] = []
    graph = nx.DiGraph()
    for module, imps in sorted(imports.items()):
        graph.add_node(module)
        mine = layer_of(module, layers)
        if mine is None or (module != package and layers[mine].modules == (package,)):
            out.append(f"{module}: in no layer of the table")
            continue
        for imp in imps:
            top = imp.target.split(".")[0]
            if top == package:
                if imp.target == module:
                    continue
                theirs = layer_of(imp.target, layers)
                graph.add_edge(module, imp.target)
                if theirs is not None and theirs > mine:
                    out.append(f"{module}:{imp.line}: imports {imp.target} of the later layer "
                               f"{layers[theirs].name!r} (it is in {layers[mine].name!r})")
            elif top not in sys.stdlib_module_names and top not in layers[mine].imports:
                out.append(f"{module}:{imp.line}: imports {top}, which layer "
                           f"{layers[mine].name!r} may not")
    for scc in nx.strongly_connected_components(graph):
        if len(scc) > 1:
            cycle = min(nx.simple_cycles(graph.subgraph(scc)), key=len)
            first = cycle.index(min(cycle))  # written from its first module, to be stable
            cycle = cycle[first:] + cycle[:first]
            out.append("import cycle: " + " -> ".join([*cycle, cycle[0]]))
    return sorted(set(out))


def test_the_package_keeps_the_layer_table_and_has_no_import_cycle():
    found = problems(read_imports(ROOT / "matedit"))
    assert found == [], "\n".join(found)


def test_every_module_is_read():
    imports = read_imports(ROOT / "matedit")
    assert {"matedit", "matedit.cli", "matedit.graph.model", "matedit.app.canvas.scene"} \
        <= imports.keys()
    # a function-local import is read (commands import the compiler inside run())
    assert "matedit.interop.export" in {i.target for i in imports["matedit.commands.compile"]}


def _package(tmp_path: Path, files: dict[str, str]) -> Path:
    root = tmp_path / "pkg"
    for rel, text in files.items():
        p = root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return root


SMALL = (Layer("base", ("pkg",)), Layer("low", ("pkg.low",), ("numpy",)),
         Layer("high", ("pkg.high",), ("PySide6",)))


def test_the_checker_reports_a_planted_breach_cycle_and_foreign_import(tmp_path):
    root = _package(tmp_path, {
        "__init__.py": "",
        "low/__init__.py": "",
        "low/a.py": "import numpy\n\ndef f():\n    from pkg.high import b\n",
        "low/c.py": "from pkg.low import d\n",
        "low/d.py": "import pkg.low.c\nimport PySide6.QtCore\n",
        "high/__init__.py": "",
        "high/b.py": "from typing import TYPE_CHECKING\nimport PySide6\nfrom pkg.low import a\n"
                     "if TYPE_CHECKING:\n    from pkg.low import c\n",
    })
    found = problems(read_imports(root), SMALL, package="pkg")
    # pkg.high.b's TYPE_CHECKING import of pkg.low.c is no edge, and its PySide6 is allowed
    assert found == [
        "import cycle: pkg.high.b -> pkg.low.a -> pkg.high.b",
        "import cycle: pkg.low.c -> pkg.low.d -> pkg.low.c",
        "pkg.low.a:4: imports pkg.high.b of the later layer 'high' (it is in 'low')",
        "pkg.low.d:2: imports PySide6, which layer 'low' may not",
    ]


def test_the_checker_reports_a_module_in_no_layer(tmp_path):
    root = _package(tmp_path, {"__init__.py": "", "stray.py": ""})
    assert problems(read_imports(root), SMALL, package="pkg") == ["pkg.stray: in no layer of "
                                                                  "the table"]


def test_the_documented_table_is_the_data():
    """docs/architecture.md's table, row by row: the layer, its modules, its third-party
    imports, in the order of matedit.layers.LAYERS."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    assert "matedit/layers.py" in text
    section = text.split("## Layers and what each may import", 1)[1].split("\n## ", 1)[0]
    rows = [r for r in section.splitlines() if r.startswith("| ") and not r.startswith("| layer")]
    cells = [[c.strip() for c in r.strip("|").split("|")] for r in rows]
    assert [c[0] for c in cells] == [layer.name for layer in LAYERS]
    for layer, row in zip(LAYERS, cells):
        doc_modules = re.findall(r"\[`([^`]+)`\]", row[1])
        paths = [m.replace(".", "/") for m in layer.modules]
        assert [d.rstrip("/").removesuffix(".py") for d in doc_modules] == paths, layer.name
        doc_imports = set(re.findall(r"`([A-Za-z0-9_]+)`", row[3]))
        assert doc_imports == set(layer.imports), layer.name
