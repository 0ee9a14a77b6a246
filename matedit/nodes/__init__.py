"""The node catalogue: one module per palette category, each kind written once.

A kind is its `NodeDef` (matedit.nodes.kind) in its category module, carrying everything
about it: ports, settings and facts; its GLSL (the function in shaders/nodes/<kind>.glsl, or
an inline template); its numpy twin (`numpy=`, a function of the same module); and its
MaterialX mapping (a stdlib node, or a recipe written through the builder the exporter passes
in). Adding a kind is adding it to its category module, plus its .glsl file when it calls a
function. No other module names a kind (tests/test_kind_contract.py).

A pure layer: no Qt, no GL, no MaterialX; numpy only for the twins. Code reads the
catalogue through `matedit.graph.nodes`. Importing this package registers every kind, in
the order of the modules below.
"""

# In this order (a kind registered first wins where two share a MaterialX recipe).
from matedit.nodes import (  # noqa: F401, I001  (each registers its kinds)
    parameters,
    maths,
    vectors,
    colour,
    noise,
    patterns,
    uv_space,
    textures,
    normals,
    masks,
    material,
)
