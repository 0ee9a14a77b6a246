"""Help › Node Reference: an index of every node kind, searchable, with a thumbnail."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import EDITOR_SAMPLE
from PySide6.QtCore import Qt
from test_app_support import app_env, make_window  # noqa: F401 - fixture

from matedit.graph import nodes

pytestmark = pytest.mark.usefixtures("app_env")


def _pixels(img) -> np.ndarray:
    """A QImage's RGB bytes as an (h, w, 3) array."""
    img = img.convertToFormat(img.Format.Format_RGB888)
    bits = np.frombuffer(img.constBits(), np.uint8, img.sizeInBytes())
    return bits.reshape(img.height(), img.bytesPerLine())[:, :img.width() * 3].reshape(
        img.height(), img.width(), 3)


def test_every_kind_gets_a_thumbnail_or_none_and_they_show_what_the_node_makes():
    from matedit.app.previews import kind_thumbnail

    made = {k: kind_thumbnail(k, 48) for k in nodes.REGISTRY}  # none may raise
    with_picture = [k for k, img in made.items() if img is not None]
    # Only kinds that need a wire, a function or a file to make anything have none.
    assert len(with_picture) >= len(made) - 8, sorted(set(made) - set(with_picture))
    assert made["material_output"] is None
    # A colour parameter at its default 0.5 grey: sRGB(0.5) = 188 inside the sphere.
    grey = _pixels(made["color_parameter"])
    assert np.abs(grey[24, 24].astype(int) - 188).max() <= 1
    # A checker alternates its two colours: sRGB(0.9) = 243 and sRGB(0.1) = 89.
    checker = _pixels(made["checker"])[12:36, 12:36, 0].ravel()
    assert {int(v) for v in np.unique(checker)} >= {243, 89}


def test_the_reference_opens_without_a_selection_and_searches(qtbot):
    w = make_window(qtbot, EDITOR_SAMPLE, show=True)
    canvas = w.tabs.material.canvas
    canvas.select_nodes([])
    help_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&Help")
    action = next(a for a in help_menu.actions() if a.text() == "&Node Reference")
    assert action.isEnabled()
    action.trigger()
    docs = w._docs
    assert docs is not None and docs.isVisible()
    every = docs.shown_kinds()
    assert sorted(every) == sorted(nodes.REGISTRY)
    assert docs.count.text() == f"{len(every)} of {len(every)} node kinds"
    assert docs.kind in every and nodes.REGISTRY[docs.kind].description in \
        docs.browser.toPlainText()

    docs.search.setText("noise")
    shown = docs.shown_kinds()
    assert "value_noise" in shown and len(shown) < len(every)
    for k in shown:
        d = nodes.REGISTRY[k]
        assert "noise" in " ".join([d.title, d.kind, d.category, d.description,
                                    *(p.name for p in (*d.inputs, *d.outputs))]).lower()
    assert docs.kind in shown  # the page follows the search
    docs.search.setText("octaves fbm")  # every word must match (a port and a name)
    assert docs.shown_kinds() and all(
        "octaves" in [p.name for p in nodes.REGISTRY[k].inputs] for k in docs.shown_kinds())

    docs.search.clear()
    item = docs._items["checker"]
    docs.tree.setCurrentItem(item)  # choosing a row shows its page and thumbnail
    assert docs.kind == "checker" and docs.windowTitle().startswith("Checker")
    assert "color_a" in docs.browser.toPlainText() and docs.has_thumbnail()

    canvas.select_nodes(["mask_noise"])  # F1 on a node opens its kind
    canvas.setFocus()
    qtbot.keyClick(canvas, Qt.Key.Key_F1)
    assert docs.kind == "value_noise"
    assert docs.tree.currentItem() is docs._items["value_noise"]
    docs.search.setText("checker")  # the shown kind is filtered out: the first match shows
    assert docs.kind == "checker"
    w.show_docs("value_noise")  # asked for a hidden kind: the search is cleared
    assert docs.kind == "value_noise" and not docs.search.text()
