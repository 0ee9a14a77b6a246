"""One source of binding numbers and block layouts (matedit/glsl/layout.py): the generated
shaders/layout.glsl is current, the GLSL block declarations have its members, GL's own block
sizes agree with its std140 arithmetic, and the packers write blocks of its sizes."""

from __future__ import annotations

import re

from matedit.compiler.emit import FRAME_BLOCK
from matedit.compiler.targets import FIRST_TEXTURE_BINDING, FRAME_BINDING, MATERIAL_BINDING
from matedit.glsl import layout
from matedit.glsl.include import assemble
from matedit.resources import shaders_dir
from matedit.shading.ibl import IBL_MODE_NONE, IBL_MODE_REFERENCE, pack_ibl_block
from matedit.shading.lights import Light
from matedit.shading.lights_block import pack_lights, unpack_lights


def test_layout_glsl_is_generated_from_the_module():
    assert (shaders_dir() / "layout.glsl").read_text() == layout.glsl_text()


def _members(glsl: str, block: str) -> list[tuple[str, str, int]]:
    body = re.search(rf"uniform {block} \{{(.*?)\}}", glsl, re.S).group(1)
    out = []
    for t, name, count in re.findall(r"^\s*(\w+)\s+(\w+)(?:\[(\w+)\])?;", body, re.M):
        out.append((t, name, count))
    return out


def test_glsl_declarations_have_the_layouts_members():
    lights = (shaders_dir() / "lights_block.glsl").read_text()
    ibl = (shaders_dir() / "ibl_inputs.glsl").read_text()
    assert [m[1] for m in _members(lights, "LightsBlock")] == \
        [m.name for m in layout.LIGHTS_BLOCK.members]
    assert [(m[0], m[1]) for m in _members(ibl, "IblBlock")] == \
        [(m.type, m.name) for m in layout.IBL_BLOCK.members]
    frame = FRAME_BLOCK.format(binding=FRAME_BINDING)
    assert [(m[0], m[1]) for m in _members(frame, "FrameBlock")] == \
        [(m.type, m.name) for m in layout.FRAME_BLOCK.members]
    # no binding number is written anywhere else as a literal define
    for path in shaders_dir().rglob("*.glsl"):
        if path.name != "layout.glsl":
            assert not re.search(r"#define MATEDIT_\w+_BINDING \d", path.read_text()), path
    assert (FRAME_BINDING, MATERIAL_BINDING, FIRST_TEXTURE_BINDING) == \
        (layout.BINDINGS["FRAME"], layout.BINDINGS["MATERIAL"], layout.BINDINGS["FIRST_TEXTURE"])


def test_gl_block_sizes_match_the_std140_arithmetic(gl_ctx):
    """GL's reflection (GL_UNIFORM_BLOCK_DATA_SIZE) of a shader using all three blocks."""
    body = FRAME_BLOCK.format(binding=FRAME_BINDING) + """
out vec4 fragColor;
void main() {
    Light l = getLight(0);
    fragColor = uFrame.params + uIbl.params + uIbl.sh[8] + uIbl.sampleOffset
              + vec4(l.position, float(lightCount())) + uFrame.viewProjection[0]
              + uFrame.model[1] + uFrame.normalMatrix[2] + uFrame.cameraPosition;
}
"""
    frag = assemble(body, "330 core", ["lights_block.glsl", "ibl_inputs.glsl"], "<test>")
    vert = "#version 330 core\nvoid main() { gl_Position = vec4(0.0); }\n"
    prog = gl_ctx.program(vertex_shader=vert, fragment_shader=frag.text)
    try:
        for block in layout.BLOCKS:
            assert prog[block.name].size == block.size, block.name
    finally:
        prog.release()


def test_packers_write_the_layouts_sizes_and_offsets():
    lights = [Light(kind="sphere", position=(1.0, 2.0, 3.0), intensity=5.0, source_radius=0.2)]
    data = pack_lights(lights)
    assert len(data) == layout.LIGHTS_BLOCK.size == 1040
    assert unpack_lights(data)[0].position == (1.0, 2.0, 3.0)
    ibl = pack_ibl_block([[0.1, 0.2, 0.3]] * 9, 7.0, 0.5, 16, IBL_MODE_REFERENCE, (0.25, 0.75),
                         True)
    assert len(ibl) == layout.IBL_BLOCK.size == 176
    import numpy as np

    rows = np.frombuffer(ibl, "<f4").reshape(-1, 4)
    offs = layout.IBL_BLOCK.offsets()
    assert tuple(rows[offs["params"] // 16]) == (7.0, 0.5, 16.0, float(IBL_MODE_REFERENCE))
    assert tuple(rows[offs["sampleOffset"] // 16]) == (0.25, 0.75, 1.0, 0.0)
    assert IBL_MODE_NONE == layout.IBL_MODES["NONE"]
