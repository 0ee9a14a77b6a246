"""A structural edit is compiled with the editor's analysis of the graph, made once when the
edit settled (DocumentController.current_analysis), not validated again by the compiler; an
analysis older than the document, or than a function file read since, is never reused."""

from __future__ import annotations

import pytest
from graphs_util import EDITOR_SAMPLE
from test_app_support import app_env  # noqa: F401 - fixture

from matedit.app.controller import DocumentController
from matedit.compiler import compile_document
from matedit.compiler import lower as lower_module
from matedit.graph.commands import SetValue
from matedit.io import document as documents
from matedit.io.document import load

pytestmark = pytest.mark.gui


@pytest.fixture
def top_analyses(monkeypatch):
    """The top-level analyses the compiler makes (with their callees)."""
    made: list[str] = []
    real = lower_module.analyse

    def counted(doc, resolver=None, *, calls=True):
        if calls:
            made.append(doc.name)
        return real(doc, resolver, calls=calls)

    monkeypatch.setattr(lower_module, "analyse", counted)
    return made


def test_the_compile_takes_the_current_analysis_and_writes_the_same_glsl(
        app_env, top_analyses):  # noqa: F811
    controller = DocumentController(load(EDITOR_SAMPLE))
    a = controller.current_analysis
    assert a is not None and a is controller.analysis
    with_it = compile_document(controller.document, controller.resolver, analysis=a)
    assert top_analyses == []  # not validated again
    without = compile_document(controller.document, controller.resolver)
    assert top_analyses == [controller.document.name]
    assert with_it.structure_hash == without.structure_hash
    assert with_it.fragment_text == without.fragment_text


def test_an_analysis_older_than_the_document_is_not_current(app_env):  # noqa: F811
    controller = DocumentController(load(EDITOR_SAMPLE))
    assert controller.current_analysis is not None
    controller.push(SetValue("mask_noise", "scale", 9.0))
    assert controller.current_analysis is None  # changed since it was made
    controller.flush()  # a value edit does not settle: the analysis stays old
    assert controller.current_analysis is None
    controller.reanalyse()
    assert controller.current_analysis is controller.analysis
    documents.LOADS += 1  # a function file read anew (changed on disk) since
    assert controller.current_analysis is None


def test_a_structural_edit_in_the_editor_is_validated_once(qtbot, app_env,  # noqa: F811
                                                          top_analyses):
    """The controller's analysis at the edit's end is the only one: the viewport's compile
    and the node thumbnails' lowering take it."""
    from test_app_support import make_window, settle

    from matedit.graph.commands import AddNode
    from matedit.graph.model import Node

    w = make_window(qtbot, EDITOR_SAMPLE)
    settle(qtbot, w)
    top_analyses.clear()
    assert w.controller.push(AddNode(Node("k_test", "constant", (0, 0),
                                          {"type": "float", "value": 0.02})))
    w.controller.flush()  # the edit settles: the controller analyses it
    w.compiler.recompile()
    w.tabs.material.previews.images()
    assert top_analyses == []
    assert w.compiler.current is not None
