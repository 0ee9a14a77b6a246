"""How each node kind of the catalogue maps to MaterialX 1.39 stdlib nodes, as data.

Keyed by catalogue kind (matedit.graph.nodes) so that it can move into the catalogue as a
per-kind field without changing its shape. An entry is one of:

  MxNode(category, ports)   one stdlib node of that category; `ports` maps our input names
                            to its inputs in order, `fixed` adds constant inputs, `output`
                            names its output. Every input is converted to the op's result
                            type first, so the same-type node definition is always chosen.
  MxRecipe(name)            a few stdlib nodes, built by matedit.interop.mtlx_export (the
                            recipe of that name) and read back by matedit.interop.mtlx_import.
  BAKE                      not expressible node for node: the exporter bakes the node's
                            outputs over UV space into EXR images read by `image` nodes.

Kinds that never reach the exporter (parameters, constants, reroutes, functions, layer
stacks: the compiler lowers them to uniforms, literals, inlined calls and blends) are listed
as LOWERED.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class MxNode:
    category: str
    ports: tuple[tuple[str, str], ...]  # (our input, MaterialX input)
    fixed: tuple[tuple[str, float], ...] = field(default_factory=tuple)
    output: str = "out"


@dataclass(frozen=True)
class MxRecipe:
    name: str


BAKE = "bake"


def _bin(cat: str) -> MxNode:
    return MxNode(cat, (("a", "in1"), ("b", "in2")))


def _un(cat: str) -> MxNode:
    return MxNode(cat, (("value", "in"),))


MTLX: dict[str, MxNode | MxRecipe | str] = {
    "add": _bin("add"),
    "subtract": _bin("subtract"),
    "multiply": _bin("multiply"),
    "divide": _bin("divide"),
    "min": _bin("min"),
    "max": _bin("max"),
    "cross": _bin("crossproduct"),
    "lerp": MxNode("mix", (("a", "bg"), ("b", "fg"), ("alpha", "mix"))),
    "clamp": MxNode("clamp", (("value", "in"), ("min", "low"), ("max", "high"))),
    "saturate": MxNode("clamp", (("value", "in"),), (("low", 0.0), ("high", 1.0))),
    "abs": _un("absval"),
    "sin": _un("sin"),
    "cos": _un("cos"),
    "floor": _un("floor"),
    "frac": MxNode("modulo", (("value", "in1"),), (("in2", 1.0),)),  # x - floor(x)
    "smoothstep": MxNode("smoothstep", (("value", "in"), ("edge0", "low"),
                                        ("edge1", "high"))),
    "remap": MxNode("remap", (("value", "in"), ("in_min", "inlow"), ("in_max", "inhigh"),
                              ("out_min", "outlow"), ("out_max", "outhigh"))),
    "one_minus": MxRecipe("one_minus"),  # subtract(1, value)
    "power": MxRecipe("power"),  # power(max(base, 0), exponent)
    "sqrt": MxRecipe("sqrt"),  # sqrt(max(value, 0))
    "step": MxRecipe("step"),  # clamp(floor(value - edge) + 1, 0, 1)
    "dot": MxRecipe("dot"),  # dotproduct, or multiply for floats
    "length": MxRecipe("length"),  # magnitude, or absval for floats
    "normalize": MxRecipe("normalize"),
    "component_mask": MxRecipe("mask"),  # extract / combineN
    "append": MxRecipe("append"),  # extract / combineN
    "split": MxRecipe("split"),  # extract per component
    "combine": MxRecipe("combine"),  # combine2/3/4
    "texcoord": MxRecipe("texcoord"),  # texcoord * tiling + offset
    "world_position": MxNode("position", (), output="out"),
    "world_normal": MxNode("normal", (), output="out"),
    "view_direction": MxRecipe("view_direction"),  # -viewdirection (ours points at the eye)
    "time": MxNode("time", ()),
    "texture_sample": MxRecipe("texture_sample"),  # image (vector4)
    "vector_parameter": MxRecipe("vector_parameter"),
    "make_attributes": MxRecipe("attributes"),
    "break_attributes": MxRecipe("attributes"),
    "set_attributes": MxRecipe("attributes"),
    "layer_blend": MxRecipe("blend"),  # a mix per field, the normal normalised
    "height_blend": MxRecipe("blend"),  # smoothstep(-c, c, dh) as the blend factor
    "value_noise": BAKE,  # our PCG-hash lattice noise: the stdlib has no integer hash
    "checker": MxRecipe("checker"),  # modulo(floor(u s) + floor(v s), 2) into a mix
    "gradient": MxRecipe("gradient"),  # clamp(dot(uv - 0.5, d) / (|dx| + |dy|) + 0.5)
    "unpack_normal": MxRecipe("unpack_normal"),  # normalize((2 p - 1) * (s, s, 1))
    "blend_normals": MxRecipe("blend_normals"),  # reoriented normal mapping
    "flatten_normal": MxRecipe("flatten_normal"),  # normalize(mix(n, +Z, flatness))
}

LOWERED = ("constant", "scalar_parameter", "color_parameter", "texture_parameter", "reroute",
           "function_input", "function_output", "function_call", "layer_stack",
           "material_output")


def mapping(kind: str) -> MxNode | MxRecipe | str:
    """The entry for `kind`; unknown kinds (added to the catalogue later) bake."""
    return MTLX.get(kind, BAKE)
