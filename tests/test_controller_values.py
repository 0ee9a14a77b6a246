"""What `DocumentController.valuesChanged` carries: the node and port of each value edit (a
non-structural setting marked as one), and one `MANY_VALUES` for a macro, applied, undone
or redone (Qt signals, no window)."""

from __future__ import annotations

import pytest
from graphs_util import material, node

pytest.importorskip("PySide6")

from matedit.app.controller import MANY_VALUES, DocumentController, ValueChange  # noqa: E402
from matedit.graph.commands import Macro, SetSetting, SetValue  # noqa: E402


def _controller():
    doc = material()
    node(doc, "a", "scalar_parameter", values={"value": 0.5})
    node(doc, "b", "scalar_parameter", values={"value": 0.25})
    node(doc, "t", "scalar_parameter")
    c = DocumentController(doc)
    seen: list[ValueChange] = []
    c.valuesChanged.connect(seen.append)
    return c, seen


def test_each_value_edit_names_its_node_and_port(qapp):
    c, seen = _controller()
    assert c.push(SetValue("a", "value", 0.75))
    assert c.push(SetValue("b", "value", 0.1))
    assert seen == [ValueChange("a", "value"), ValueChange("b", "value")]
    assert seen[0].touches("a") and not seen[0].touches("b") and not seen[0].many
    c.undo_stack.undo()
    assert seen[-1] == ValueChange("b", "value")


def test_a_non_structural_setting_is_marked_as_one(qapp):
    c, seen = _controller()
    assert c.push(SetSetting("t", "ui_max", 2.0))
    assert seen == [ValueChange("t", "ui_max", setting=True)]


def test_a_macro_is_announced_once_as_many(qapp):
    c, seen = _controller()
    assert c.push(Macro([SetValue("a", "value", 0.9), SetValue("b", "value", 0.8)], text="m"))
    assert seen == [MANY_VALUES] and MANY_VALUES.many and MANY_VALUES.touches("anything")
    c.undo_stack.undo()
    c.undo_stack.redo()
    assert seen == [MANY_VALUES] * 3
    assert c.document.graph.nodes["a"].values["value"] == 0.9
