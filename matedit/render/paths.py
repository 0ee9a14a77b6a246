"""Which path a material takes in the preview, forward or deferred, decided from its IR and
uniform values alone, and how its link went (`MaterialStatus`): no GL here, so the editor's
process reads both without moderngl (the render process sends the status back)."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class MaterialStatus:
    ok: bool
    errors: list[tuple[str, str]] = field(default_factory=list)  # (node id, message)
    log: str = ""


def _opacity_index() -> int:
    from matedit.graph import nodes

    make = nodes.definition(nodes.kind_for(nodes.Role.MAKE_ATTRIBUTES))
    return [i.name for i in make.inputs].index("opacity")


def _is_one(e, values: dict) -> bool:
    """A literal 1, or a uniform whose current value is at least 1 (the forward entry clamps
    opacity to [0, 1], so it draws those fully opaque)."""
    from matedit.compiler.ir import Lit, Splat, Uni

    while isinstance(e, Splat):
        e = e.expr
    if isinstance(e, Lit):
        return e.value == 1.0
    if isinstance(e, Uni):
        try:
            return float(values[e.name]) >= 1.0
        except (KeyError, TypeError, ValueError):
            return False
    return False


def may_be_translucent(ir, values: dict | None = None) -> bool:
    """Whether any code of the material can give an opacity other than 1 with these uniform
    values: a MakeAttributes whose opacity is not 1 (a literal, or a uniform now at 1 or
    above), or a SetAttributes of opacity, in any scope (through layers and functions too).
    Conservative: anything computed counts as translucent."""
    values = {u.name: u.default for u in ir.uniforms} | dict(values or {})
    if "opacity" not in ir.attributes:
        return False
    from matedit.graph.nodes import Role, role_of

    k = _opacity_index()
    for scope in [ir.main, *ir.functions]:
        for op in scope.ops:
            role = role_of(op.kind)
            if role == Role.MAKE_ATTRIBUTES and not _is_one(op.args[k], values):
                return True
            if role == Role.SET_ATTRIBUTES and "opacity" in op.data.get("fields", ()):
                return True
    return False


def writes_lobes(ir) -> bool:
    """Whether the material writes a field beyond the talk's model (specular colour, IOR,
    coat, sheen, anisotropy): the G-buffer holds only the talk's fields."""
    from matedit.graph.nodes import ATTRIBUTE_FIELDS

    return any(f.lobe and f.name in ir.attributes for f in ATTRIBUTE_FIELDS)


def wants_forward(compiled, values: dict | None = None) -> bool:
    """Translucent materials are blended in draw order (every layer of the mesh), which a
    G-buffer of the nearest surface cannot reproduce: they take the forward path. A value edit
    that makes a material translucent moves it there (one link, the first time). Materials
    with lobes beyond the talk take it too, so the G-buffer and the one lighting pass stay the
    talk's for every other material."""
    return writes_lobes(compiled.ir) or may_be_translucent(compiled.ir, values)
