"""Emission: the optimised IR to vertex and fragment text for one target.

Two halves: `schedule` lays the IR out for an entry point with nothing of any language in it
(scope order, local names, library units, defines, the uniform block's layout), and a back-end
writes it; `glsl_backend` is the one there is (glsl330, glsl450, essl300 differ by version and
prelude; HLSL and MSL are translated from glsl450 by `matedit.interop.cross`).

The fragment stage includes the shading library (`surface`); the generated code fills a
MaterialAttributes in `evaluateMaterial()` and never sees lights. Every generated line records
the node it came from (`SourceMap`), so a GL compile error is reported on the node.
"""

from __future__ import annotations

from matedit.compiler import glsl_backend
from matedit.compiler.glsl_backend import FRAME_BLOCK, entry_text, float_literal, vertex_source
from matedit.compiler.ir import MaterialIR
from matedit.compiler.schedule import (
    ENTRY_OUTPUTS,
    PREVIEW_DEFINES,
    SKIP_HIDDEN_LAYERS,
    Entry,
    SourceMap,
    has_defines,
    schedule,
    std140_layout,
)
from matedit.compiler.targets import Target
from matedit.glsl.include import Assembly

__all__ = ["ENTRY_OUTPUTS", "FRAME_BLOCK", "PREVIEW_DEFINES", "SKIP_HIDDEN_LAYERS", "Entry",
           "SourceMap", "entry_text", "float_literal", "fragment_source", "has_defines",
           "std140_layout", "vertex_source"]


def fragment_source(ir: MaterialIR, target: Target, mode: str | Entry = Entry.FORWARD,
                    defines: tuple[str, ...] | list[str] = ()) -> tuple[Assembly, SourceMap]:
    """The fragment stage of one entry; `defines` are extra feature defines after the
    material's own (the preview's MATEDIT_SPLIT_SUM_ONLY, MATEDIT_ENERGY_COMPENSATION,
    MATEDIT_SKIP_HIDDEN_LAYERS)."""
    return glsl_backend.fragment_source(schedule(ir, mode, defines), target)

