"""The CPU evaluator: the same IR evaluated with numpy over arrays of pixels.

It is the reference the compiled GLSL is tested against, and lets the editor
probe any socket. It evaluates the IR before optimisation, so the optimiser is
checked too. Floats are arrays of shape (N,), vectors (N, k), MaterialAttributes
dicts of such arrays, textures (H, W, 4) float arrays.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from matedit.compiler import ops
from matedit.compiler.ir import Expr, Lit, MaterialIR, Op, Param, Scope, Splat, SurfaceUV, Uni, Var
from matedit.graph.nodes import ATTRIBUTE_FIELDS
from matedit.graph.types import PortType


def default_attributes(n: int) -> dict[str, np.ndarray]:
    out = {}
    for f in ATTRIBUTE_FIELDS:
        v = np.asarray(f.default, dtype=np.float64)
        out[f.name] = np.broadcast_to(v, (n,) + v.shape).copy()
    return out


def checker_texture(size: int = 8) -> np.ndarray:
    """What a missing texture shows: a magenta and grey checker, visible and not an error."""
    ij = np.add.outer(np.arange(size), np.arange(size)) % 2
    img = np.where(ij[..., None] == 0, [1.0, 0.0, 1.0, 1.0], [0.2, 0.2, 0.2, 1.0])
    return img.astype(np.float32)


@dataclass
class Env:
    surface: Any  # cpu_nodes.SurfaceArrays
    n: int
    uniforms: dict[str, Any] = field(default_factory=dict)
    textures: dict[str, np.ndarray] = field(default_factory=dict)
    functions: dict[str, Scope] = field(default_factory=dict)

    def call(self, function: str, args: list[Any]) -> tuple:
        """The outputs of the material function `function` for its argument values (the op
        table's call row evaluates through this, not through this module)."""
        scope = self.functions[function]
        return eval_scope(scope, dict(zip((p for p, _ in scope.params), args)), self)


def _broadcast(value, t: PortType, n: int) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64)
    if t == PortType.FLOAT:
        return np.full((n,), float(v.reshape(-1)[0]))
    return np.broadcast_to(v.reshape(-1), (n, t.components)).copy()


def eval_expr(e: Expr, table: dict[str, Any], env: Env | None) -> Any:
    if isinstance(e, Var):
        return table[e.name]
    if isinstance(e, Param):
        return table[e.name]
    if isinstance(e, Lit):
        n = env.n if env else 1
        if e.type == PortType.MATERIAL:
            return default_attributes(n)
        return _broadcast(e.value, e.type, n)
    if env is None:  # constant folding: nothing else has a value without a surface
        raise TypeError(f"{e!r} has no value without a surface")
    if isinstance(e, Uni):
        if e.type == PortType.TEXTURE:
            return env.textures.get(e.name, checker_texture())
        return _broadcast(env.uniforms[e.name], e.type, env.n)
    if isinstance(e, SurfaceUV):
        return np.asarray(env.surface.uv, dtype=np.float64)
    if isinstance(e, Splat):
        inner = np.asarray(eval_expr(e.expr, table, env), dtype=np.float64)
        return np.repeat(inner.reshape(-1, 1), e.type.components, axis=1)
    raise TypeError(f"cannot evaluate {e!r}")


def eval_op(op: Op, args: list[Any], env: Env | None) -> tuple:
    """The op's outputs from its operand values, by its row in the op table (`ops`); `env`
    None: constant folding, where ops that read the surface or call a function refuse."""
    return ops.implementation(op.kind).numpy(op, args, env)


def eval_scope(scope: Scope, params: dict[str, Any], env: Env,
               probe: dict[str, Any] | None = None) -> tuple:
    table: dict[str, Any] = dict(params)
    for op in scope.ops:
        args = [eval_expr(a, table, env) for a in op.args]
        values = eval_op(op, args, env)
        for (port, _), v in zip(op.outs, values):
            table[op.out(port).name] = v
    if probe is not None:
        for key, e in scope.sockets.items():
            try:
                probe[f"{key[0]}.{key[1]}"] = eval_expr(e, table, env)
            except KeyError:
                pass
    return tuple(eval_expr(e, table, env) for _, _, e in scope.outputs)


def evaluate(ir: MaterialIR, surface, uniforms: dict[str, Any] | None = None,
             textures: dict[str, np.ndarray] | None = None,
             probe: dict[str, Any] | None = None) -> dict[str, np.ndarray]:
    """The MaterialAttributes of the material at each pixel of `surface`.

    `uniforms` overrides the defaults by uniform name; pass a dict as `probe` to
    receive every top-level socket's value as "node.port". `textures` gives linear arrays
    by uniform name; the others are read from their files and decoded to linear by their
    colour space, as the renderer does (a missing or unreadable file shows the checker).
    """
    n = np.asarray(surface.uv).shape[0]
    values = {u.name: u.default for u in ir.uniforms}
    values.update(uniforms or {})
    tex = dict(textures or {})
    for t in ir.textures:
        if t.name not in tex and t.path:
            tex[t.name] = _linear_texture(t)
    env = Env(surface, n, values, tex, {f.name: f for f in ir.functions})
    (attrs,) = eval_scope(ir.main, {}, env, probe)
    return attrs


def _linear_texture(t) -> np.ndarray:
    """A texture file decoded to linear RGBA by its colour space (matedit.shading.colorspace),
    or the checker when the file cannot be read."""
    from matedit.shading.colorspace import effective_space, load_texture_cached

    try:
        space = effective_space(getattr(t, "color_space", ""), t.srgb)
        return load_texture_cached(t.path, space).linear
    except (ValueError, OSError):
        return checker_texture()
