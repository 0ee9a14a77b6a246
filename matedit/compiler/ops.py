"""The one table of op implementations, read by every back-end and by the CPU evaluator.

An `Op` of the IR is either a catalogue node kind (its GLSL function or inline template and
its numpy twin are its definition's, `NodeDef.glsl` / `inline` / `numpy`) or one of
the compiler's own ops below (swizzle, construction, field assignment, layer weight, blend and
coat, material-function call). `implementation(kind)` answers both the same way, so the emitter and
the evaluator each dispatch once, from here, and cannot disagree on what an op means.

A row's `glsl` is a value template read only by the GLSL back-end
(`matedit.compiler.glsl_backend`): `{0}`, `{1}` are the operands, `{args}` all of them
comma-separated, `{T}` the result's type name in the back-end's language, any other `{name}`
an input of the catalogue kind or a key of the op's data. `glsl=None` means the kind's
definition says (its `inline` template, or the `glsl` function it calls with out parameters),
or for a material-function call the op's data (`function`).
A new back-end adds its own column; the numpy column is the reference all of them are tested
against.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from matedit.compiler.ir import Op
from matedit.graph.nodes import Role, get, kind_for, role_of

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np


# The compiler's own op kinds (`Op.kind`); interop.mtlx_export and render.deferred read them.
MASK = "mask"  # a component swizzle, op.data["channels"]
# Two catalogue kinds are the compiler's own ops too; the catalogue names them by role.
APPEND = Role.APPEND  # a vector built from its operands, in order
SET_ATTRIBUTES = Role.SET_ATTRIBUTES  # a MaterialAttributes with op.data["fields"] replaced
WEIGHT = "weight"  # a layer's alpha weight: saturate(mask * opacity)
BLEND = "blend"  # blendMaterialAttributes(base, layer, weight)
COAT = "coat"  # coatMaterialAttributes(base, layer, weight): a layer laid on as a clear coat
FILM = "film"  # filmMaterialAttributes(base, layer, weight): the layer's thin film laid on
CALL = "call"  # a material function, op.data["function"]

# The numpy column: fn(op, operand values, env) -> output values in `op.outs` order; env is a
# cpu_eval.Env, or None while constant folding (no surface, no functions).
NumpyFn = Callable[[Op, list, Any], tuple]


@dataclass(frozen=True)
class OpImpl:
    kind: str | Role  # a compiler op's name, or the role of the catalogue kind it implements
    numpy: NumpyFn
    glsl: str | None = None  # value template (see the module doc); None: the op's data says
    # op.data key of the struct fields that operands 1.. are assigned to, after the value
    assigns: str | None = None
    # library units the op's code needs (the back-end includes its file of each)
    units: tuple[str, ...] = ()


def _mask(op: Op, args: list, env) -> tuple:
    idx = ["xyzw".index(c) for c in op.data["channels"]]
    a = np.asarray(args[0])
    r = a.reshape(a.shape[0], -1)[:, idx]
    return (r[:, 0] if len(idx) == 1 else r,)


def _append(op: Op, args: list, env) -> tuple:
    parts = [np.asarray(a).reshape(np.asarray(a).shape[0], -1) for a in args]
    return (np.concatenate(parts, axis=1),)


def _set_attributes(op: Op, args: list, env) -> tuple:
    m = {f: np.array(v, copy=True) for f, v in args[0].items()}
    for name, v in zip(op.data["fields"], args[1:]):
        m[name] = np.asarray(v, dtype=np.float64)
    return (m,)


def _weight(op: Op, args: list, env) -> tuple:
    return (np.clip(np.asarray(args[0]) * np.asarray(args[1]), 0.0, 1.0),)


def _blend(op: Op, args: list, env) -> tuple:
    from matedit.nodes.material import blend_material_attributes

    return (blend_material_attributes(args[0], args[1], np.asarray(args[2])),)


def _coat(op: Op, args: list, env) -> tuple:
    from matedit.nodes.material import coat_material_attributes

    return (coat_material_attributes(args[0], args[1], np.asarray(args[2])),)


def _film(op: Op, args: list, env) -> tuple:
    from matedit.nodes.material import film_material_attributes

    return (film_material_attributes(args[0], args[1], np.asarray(args[2])),)


def _call(op: Op, args: list, env) -> tuple:
    if env is None:
        raise TypeError("a material function call is not folded")
    return env.call(op.data["function"], args)


BUILTINS: dict[str | Role, OpImpl] = {o.kind: o for o in (
    OpImpl(MASK, _mask, glsl="({0}).{channels}"),
    OpImpl(APPEND, _append, glsl="{T}({args})"),
    OpImpl(SET_ATTRIBUTES, _set_attributes, glsl="{0}", assigns="fields"),
    OpImpl(WEIGHT, _weight, glsl="clamp({0} * {1}, 0.0, 1.0)"),
    OpImpl(BLEND, _blend, glsl="blendMaterialAttributes({args})", units=("nodes/layer_blend",)),
    OpImpl(COAT, _coat, glsl="coatMaterialAttributes({args})", units=("nodes/layer_blend",)),
    OpImpl(FILM, _film, glsl="filmMaterialAttributes({args})", units=("nodes/layer_blend",)),
    OpImpl(CALL, _call),  # the back-end's call convention, on op.data["function"]
)}


def _catalogue(kind: str) -> OpImpl:
    def numpy(op: Op, args: list, env) -> tuple:
        d = get(kind)
        fn = d.numpy if d is not None else None
        if fn is None:
            raise KeyError(f"no numpy implementation for node kind {kind!r}")
        out = fn(env.surface if env else None, *args)
        return out if isinstance(out, tuple) else (out,)

    return OpImpl(kind, numpy)


_CACHE: dict[str, OpImpl] = {k: o for k, o in BUILTINS.items() if isinstance(k, str)}


def op_kind(kind: str | Role) -> str:
    """The `Op.kind` of a compiler op name or of the catalogue kind playing a role."""
    return kind_for(kind) if isinstance(kind, Role) else kind


def implementation(kind: str) -> OpImpl:
    """The row of an op kind: a compiler op's own, or a catalogue kind's (from its
    definition)."""
    impl = _CACHE.get(kind)
    if impl is None:
        role = role_of(kind)
        impl = _CACHE[kind] = (BUILTINS.get(role) if role is not None else None) or \
            _catalogue(kind)
    return impl
