"""The compiler's view of the numpy twins: each kind's twin is `NodeDef.numpy`, written next
to its definition in its category module of `matedit.nodes` (shared pieces in
`matedit.nodes.twin`).

`IMPLS[kind](ctx, *inputs)` returns the node's outputs as a tuple in declaration order (see
`matedit.nodes.twin` for the shapes); it reads the registry, so it always holds exactly the
kinds that have a twin. The compiler evaluates the kinds in `COMPILER_HANDLED` itself.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from typing import Any

from matedit.graph.nodes import REGISTRY, kinds_where
from matedit.nodes.twin import SurfaceArrays

__all__ = ["COMPILER_HANDLED", "IMPLS", "NumpyTwin", "SurfaceArrays"]

# Kinds with no numpy twin: the compiler evaluates them from the graph itself.
COMPILER_HANDLED = kinds_where(lambda d: d.lowered)

# A node kind's numpy twin: fn(surface, *inputs) -> its outputs, a tuple in declaration order
# (one output may come bare: an array, or a MaterialAttributes dict).
NumpyTwin = Callable[..., Any]


class _Twins(Mapping[str, NumpyTwin]):
    """kind -> its definition's numpy twin, for the kinds that have one."""

    def __getitem__(self, kind: str) -> NumpyTwin:
        d = REGISTRY.get(kind)
        if d is None or d.numpy is None:
            raise KeyError(kind)
        return d.numpy

    def __iter__(self) -> Iterator[str]:
        return (k for k, d in REGISTRY.items() if d.numpy is not None)

    def __len__(self) -> int:
        return sum(1 for _ in self)


IMPLS: Mapping[str, NumpyTwin] = _Twins()
