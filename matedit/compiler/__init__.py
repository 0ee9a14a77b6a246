"""Graph to GLSL: typed IR, optimisation, emission per target, reflection, CPU evaluator."""

from matedit.compiler.api import (
    CompiledMaterial,
    CompileError,
    compile_all,
    compile_document,
    lower_and_optimise,
)
from matedit.compiler.targets import TARGETS

__all__ = ["TARGETS", "CompileError", "CompiledMaterial", "compile_all", "compile_document",
           "lower_and_optimise"]
