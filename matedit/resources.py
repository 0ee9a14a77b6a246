"""The one place that finds shaders/, graphs/ and ui/.

In a checkout (and an editable install) they sit beside the package; in an
installed wheel they ship inside it as matedit/shaders and friends.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

_PKG = Path(__file__).resolve().parent
_KINDS = ("shaders", "graphs", "ui")


@cache
def resource_dir(kind: str) -> Path:
    """Directory of one resource kind: 'shaders', 'graphs' or 'ui'."""
    if kind not in _KINDS:
        raise ValueError(f"unknown resource kind {kind!r}; expected one of {_KINDS}")
    for candidate in (_PKG / kind, _PKG.parent / kind):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(
        f"matedit resource folder {kind!r} not found next to {_PKG} (broken install?)"
    )


def shaders_dir() -> Path:
    return resource_dir("shaders")


def graphs_dir() -> Path:
    return resource_dir("graphs")


def ui_dir() -> Path:
    return resource_dir("ui")
