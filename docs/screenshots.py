"""Makes the user guide's screenshots (docs/images/*.png) from real editor windows.

    .venv/bin/python docs/screenshots.py        # about a minute; starts Xvfb itself

Run it again after a UI change. Without a display it re-runs itself under
`xvfb-run -a -s "-screen 0 1600x1000x24"` with QT_QPA_PLATFORM=xcb; settings and
autosaves go to a temporary folder, so the shots show the default layout and your
own settings are untouched.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "images"
SAMPLE = ROOT / "graphs" / "materials" / "rusty_painted_metal.json"


def reexec_under_xvfb() -> int:
    xvfb = shutil.which("xvfb-run")
    if xvfb is None:
        print("error: no display and no xvfb-run (apt install xvfb xauth)", file=sys.stderr)
        return 2
    home = tempfile.mkdtemp(prefix="matedit-shots-")
    shutil.copytree(ROOT / "graphs", Path(home) / "graphs")  # no checkout path in the shots
    env = dict(os.environ, MATEDIT_SHOTS_CHILD=home, QT_QPA_PLATFORM="xcb",
               XDG_CONFIG_HOME=f"{home}/config", XDG_DATA_HOME=f"{home}/data")
    try:
        return subprocess.call([xvfb, "-a", "-s", "-screen 0 1600x1000x24", sys.executable,
                                __file__, *sys.argv[1:]], env=env)
    finally:
        shutil.rmtree(home, ignore_errors=True)


def shoot_interop_export(w, folder: Path, save) -> None:
    """docs/images/interop-export.png: the MaterialX export dialog after exporting the
    window's material into `folder` (gltf_pbr, PNG maps, 256 texels, round trip checked)."""
    folder.mkdir(parents=True, exist_ok=True)
    dlg = w.menus.interop.export_dialog("mtlx")
    dlg.set_output(folder / "rusty_painted_metal.mtlx")
    dlg.size.setCurrentIndex(dlg.size.findData(256))
    dlg.surface.setCurrentIndex(dlg.surface.findData("gltf_pbr"))
    dlg.check.setChecked(True)
    dlg.show()
    if not dlg.run_export():
        raise SystemExit(f"error: the MaterialX export failed: {dlg.result.toPlainText()}")
    save(dlg, "interop-export.png")
    dlg.close()


def main() -> int:
    if not os.environ.get("MATEDIT_SHOTS_CHILD"):
        return reexec_under_xvfb()
    sys.path.insert(0, str(ROOT))
    from PySide6.QtCore import QBuffer, QByteArray, QIODevice, Qt

    from matedit.app.app import make_application
    from matedit.app.main_window import MainWindow
    from matedit.io.atomic import atomic_write_bytes

    app = make_application()
    written: list[str] = []

    def pump(seconds: float = 0.3) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            app.processEvents()
            time.sleep(0.01)

    def wait(cond, timeout: float = 120.0, what: str = "") -> None:
        end = time.monotonic() + timeout
        while not cond():
            if time.monotonic() > end:
                raise SystemExit(f"error: timed out waiting for {what}")
            app.processEvents()
            time.sleep(0.02)

    def save(widget, name: str) -> None:
        pump(0.4)
        pixmap = widget.grab()
        data = QByteArray()
        buf = QBuffer(data)
        buf.open(QIODevice.OpenModeFlag.WriteOnly)
        pixmap.save(buf, "PNG")
        buf.close()
        atomic_write_bytes(OUT / name, bytes(data))
        written.append(f"{name} ({pixmap.width()}x{pixmap.height()})")

    graphs = Path(os.environ["MATEDIT_SHOTS_CHILD"]) / "graphs"
    w = MainWindow(graphs / SAMPLE.relative_to(ROOT / "graphs"))
    w.actions.ask_save_changes = lambda name: "discard"
    w.resize(1480, 900)
    w.show()
    view = w.viewport.view
    wait(lambda: view.frames > 0 and w.compiler.current is not None and view.environment_ready,
         what="the first frame and the environment after it")
    canvas = w.tabs.material.canvas
    canvas.frame_all()
    pump(1.0)

    # 1. The whole window on the sample layered material.
    save(w, "editor.png")

    # 2. The layer stack selected: Layers panel and Inspector.
    from matedit.graph.layers import LayerStack

    stack = LayerStack.find(w.controller.document.graph)
    canvas.select_nodes([stack.node_id])
    w.layers.select_layer(stack.layers[-1].id)
    pump(0.5)
    save(w.panels.layers_dock, "layers-panel.png")
    save(w.panels.inspector_dock, "inspector.png")

    # 3. A material function opened in its own tab, with breadcrumbs back.
    fn = w.tabs.open_function(graphs / "functions" / "edge_wear.json")
    if fn is not None:
        pump(0.8)  # the new tab fits its graph when it is first shown
        fn.canvas.scale(2.2, 2.2)  # close enough to read the nodes: the middle of the graph
        fn.canvas.centerOn(fn.canvas.scene().itemsBoundingRect().center())
        pump(0.8)
        save(w.tabs, "function-tab.png")
        w.tabs.activate(w.tabs.material)
        pump(0.3)

    # 4. The node palette (Tab on the canvas).
    canvas.frame_all()
    pump(0.3)
    canvas.open_palette(canvas.mapToScene(canvas.viewport().rect().center()))
    canvas.node_palette.search.setText("blend")  # what typing does: the list filters
    pump(0.5)
    save(w.tabs, "palette.png")
    canvas.node_palette.close_palette()
    canvas.frame_all()
    pump(0.3)

    # 5. Viewport modes: split sum, converged reference, difference heat map.
    save(w.panels.viewport_dock, "viewport-splitsum.png")
    for label, name in (("Reference", "viewport-reference.png"),
                        ("Difference", "viewport-difference.png")):
        w.viewport.mode_combo.setCurrentText(label)
        wait(lambda: view.renderer.converged, timeout=300, what=f"{label} to converge")
        pump(0.5)
        save(w.panels.viewport_dock, name)
    w.viewport.mode_combo.setCurrentText("Split-sum")
    pump(0.5)

    # 6. Lights & Environment, with the sky environment and a tube light added.
    w.panels.lights_dock.raise_()
    w.lights.add_light("tube")
    w.viewport.choose_environment("sky")
    pump(1.0)
    save(w.panels.lights_dock, "lights.png")
    save(w.panels.viewport_dock, "viewport-sky.png")

    # 7. Export dialog.
    from matedit.app.export_dialog import ExportDialog

    dlg = ExportDialog(w.controller.document, w.controller.resolver, w)
    dlg.show()
    pump(0.5)
    save(dlg, "export.png")
    dlg.close()

    # 7b. File > Export MaterialX's options, after an export with the round trip checked.
    shoot_interop_export(w, graphs.parent / "exports", save)

    # 8. Preview in viewport: a noise node's value on the mesh, with the banner.
    from matedit.app.node_preview import PreviewTarget

    graph = w.controller.document.graph
    from matedit.graph.nodes import definition

    noise = next(nid for nid, n in sorted(graph.nodes.items()) if nid == "mask")
    port = definition(graph.nodes[noise].kind).outputs[0].name
    before = w.compiler.current
    assert w.compiler.set_preview(PreviewTarget(noise, port)), (noise, port)
    wait(lambda: w.compiler.current is not before, what="the node preview to compile")
    pump(1.5)
    save(w.panels.viewport_dock, "viewport-node-preview.png")
    w.compiler.set_preview(None)
    pump(1.0)

    # 8b. View > A/B Split: the rust mask bypassed (B) against the material before it (A).
    canvas.select_nodes(["mask"])
    before = w.compiler.current
    canvas.toggle_bypass()
    w.controller.flush()
    wait(lambda: w.compiler.current is not before, what="the bypassed material")
    w.viewport.set_comparing(True)
    pump(1.5)
    save(w.panels.viewport_dock, "viewport-ab-split.png")
    w.viewport.set_comparing(False)
    w.controller.undo_stack.undo()
    w.controller.flush()
    pump(1.0)

    # 9. Zoomed out: titles stay readable, port labels hide.
    canvas.frame_all()
    canvas.resetTransform()
    canvas.scale(0.33, 0.33)
    canvas.centerOn(canvas.scene().itemsBoundingRect().center())
    pump(0.5)
    save(w.tabs, "canvas-overview.png")
    canvas.frame_all()

    # 10. Help > Keyboard Shortcuts, searchable.
    ref = w.show_shortcuts()
    ref.resize(560, 640)
    pump(0.5)
    save(ref, "shortcuts.png")
    ref.close()

    # 11. View > Cost Overlay and View > Stats: nodes tinted by their instructions, the Layers
    # panel's cost column, the per-target totals (computed off the UI thread).
    w.tabs.canvas_actions["cost_overlay"].trigger()
    w.stats.dock.show()
    w.stats.dock.raise_()
    wait(lambda: canvas.cost_overlay.report is not None and w.stats.panel.report is not None,
         timeout=300.0, what="the cost figures")
    w.resizeDocks([w.stats.dock], [330], Qt.Orientation.Vertical)
    w.panels.inspector_dock.raise_()
    canvas.frame_all()
    pump(1.0)
    save(w, "cost-overlay.png")
    w.tabs.canvas_actions["cost_overlay"].trigger()
    w.stats.dock.close()

    # 12. A broken link: the Diagnostics panel names the node.
    from matedit.graph.commands import Disconnect

    link = next(l for l in w.controller.document.graph.links if l.dst == "out")
    w.controller.push(Disconnect(link))
    pump(1.0)
    w.panels.diagnostics_dock.raise_()
    pump(0.3)
    save(w, "diagnostics.png")

    w.controller.undo_stack.setClean()
    w.close()
    print("wrote " + ", ".join(written) + f" into {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
