"""A compiled material whose GLSL the driver refuses, for the viewport's tests: module level, so
that it pickles into the render process (which imports this module by the editor's path)."""

from matedit.compiler.api import CompiledMaterial

BROKEN_GLSL = "#version 330 core\nvoid main() { this is not glsl; }\n"


class BrokenMaterial(CompiledMaterial):
    """Every variant the renderer asks for is this one, whose fragment does not compile."""

    fragment_text = property(lambda self: BROKEN_GLSL)

    def variant(self, entry, defines=()):  # the renderer links entry variants
        return self
