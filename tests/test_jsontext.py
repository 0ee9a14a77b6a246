"""matedit.io.jsontext's quick check (`_plainly_fine`) never passes a value its located walk
(`_walk`) refuses: at the depth limit, at the 64-bit bounds, and on types JSON does not
parse to (which the walk, not the quick check, decides)."""

from __future__ import annotations

from collections import OrderedDict

import pytest

from matedit.io import jsontext
from matedit.io.jsontext import MAX_DEPTH, MAX_FLOAT_INT, JSONTextError


def _nest(n: int, leaf: object = 1) -> object:
    v = leaf
    for _ in range(n):
        v = [v]
    return v


CASES = [
    _nest(MAX_DEPTH - 1), _nest(MAX_DEPTH), _nest(MAX_DEPTH + 1), _nest(MAX_DEPTH - 1, {}),
    _nest(MAX_DEPTH - 2, {"a": []}), _nest(MAX_DEPTH - 1, {"a": []}),
    {"a": float("inf")}, [float("-inf")], [float("nan")], {"a": MAX_FLOAT_INT},
    {"a": MAX_FLOAT_INT + 1}, [-MAX_FLOAT_INT - 1], [True, False, None, "x", 1.5, -0.0, 3],
    [(1, 2)], {"a": (float("inf"),)}, OrderedDict(a=[float("inf")]), OrderedDict(a=[1.0]),
]


def _walk_passes(value) -> bool:
    try:
        jsontext._walk(value)
    except JSONTextError:
        return False
    return True


@pytest.mark.parametrize("value", CASES)
def test_the_quick_check_passes_only_what_the_walk_passes(value):
    if jsontext._plainly_fine(value):
        assert _walk_passes(value)


def test_the_quick_check_passes_plain_documents():
    # what it is for: a plain document is judged without the walk
    assert jsontext._plainly_fine({"nodes": [{"id": "a", "values": {"x": [0.5, 1, 2]}}],
                                   "deep": _nest(MAX_DEPTH - 1, 1.0), "flag": True})
    assert not _walk_passes(_nest(MAX_DEPTH + 1)) and not jsontext._plainly_fine(
        _nest(MAX_DEPTH + 1))
