"""Node preview thumbnails come from the CPU evaluator and follow edits."""

from __future__ import annotations

import numpy as np
import pytest
from graphs_util import EDITOR_SAMPLE
from test_app_support import app_env  # noqa: F401 - fixture

from matedit.app.controller import DocumentController
from matedit.app.previews import NodePreviews, preview_sphere
from matedit.graph.commands import SetValue
from matedit.io.document import load

pytestmark = pytest.mark.gui


def _image_bytes(img) -> bytes:
    return bytes(img.constBits())


def test_pattern_nodes_get_thumbnails_that_follow_value_edits(qtbot, app_env):  # noqa: F811
    from matedit.app.canvas import NodeCanvasView

    doc = load(EDITOR_SAMPLE)
    controller = DocumentController(doc)
    canvas = NodeCanvasView(controller)
    qtbot.addWidget(canvas)
    previews = NodePreviews(controller, canvas)
    images = previews.images()
    assert "mask_noise" in images and "stack" in images  # a pattern and the layer stack
    assert "edge" not in images  # plain maths shows only when selected
    before = _image_bytes(images["mask_noise"])
    controller.push(SetValue("mask_noise", "scale", 13.0))
    after = _image_bytes(previews.images()["mask_noise"])
    assert before != after
    canvas.select_nodes(["edge"])
    assert "edge" in previews.images()
    previews.refresh()  # evaluated on the worker thread, shown when it is done
    qtbot.waitUntil(lambda: canvas.scene().node_item("mask_noise")._preview is not None,
                    timeout=30000)


def test_preview_sphere_faces_the_viewer():
    surface, inside = preview_sphere(16)
    n = surface.normal[inside]
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0)
    assert np.all(n[:, 2] >= 0) and np.all((surface.uv >= 0) & (surface.uv <= 1))
