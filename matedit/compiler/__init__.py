"""Graph to GLSL: typed IR, optimisation, emission per target, reflection, CPU evaluator.

The names below load on first use (PEP 562), so that `matedit.compiler.targets` and the
command line's start-up stay light.
"""

from __future__ import annotations

from importlib import import_module

_EXPORTS = {
    "CompiledMaterial": "matedit.compiler.api",
    "CompileError": "matedit.compiler.lower",
    "compile_all": "matedit.compiler.api",
    "compile_document": "matedit.compiler.api",
    "lower_and_optimise": "matedit.compiler.api",
    "TARGETS": "matedit.compiler.targets",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'matedit.compiler' has no attribute {name!r}")
    return getattr(import_module(module), name)
