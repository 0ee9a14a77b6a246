"""Names that reach generated code: the one rule for what a file may call things.

Every name a document gives (node ids, parameter names, function inputs and outputs, layer
ids) must be an ASCII identifier `[A-Za-z_][A-Za-z0-9_]*` of at most `MAX_NAME` characters,
with no double underscore and no `gl_` prefix (both reserved in GLSL), and not a GLSL
keyword or reserved word. The compiler still never writes such a name bare: it adds a prefix
that marks its name space (`p_` parameters, `t_` textures, `u_` unconnected inputs, `in_` and
`out_` function ports, `l_` locals, `fn_` functions), so user and generated names cannot meet.
"""

from __future__ import annotations

import re

MAX_NAME = 64
_ASCII_ID = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z", re.ASCII)

# GLSL 4.60 and ESSL 3.00 keywords and reserved words (GLSL 4.60 section 3.6, ESSL 3.00 3.7).
GLSL_KEYWORDS = frozenset("""
const uniform buffer shared attribute varying coherent volatile restrict readonly writeonly
atomic_uint layout centroid flat smooth noperspective patch sample invariant precise break
continue do for while switch case default if else subroutine in out inout int void bool true
false float double discard return vec2 vec3 vec4 ivec2 ivec3 ivec4 bvec2 bvec3 bvec4 uint
uvec2 uvec3 uvec4 dvec2 dvec3 dvec4 mat2 mat3 mat4 mat2x2 mat2x3 mat2x4 mat3x2 mat3x3 mat3x4
mat4x2 mat4x3 mat4x4 dmat2 dmat3 dmat4 dmat2x2 dmat2x3 dmat2x4 dmat3x2 dmat3x3 dmat3x4
dmat4x2 dmat4x3 dmat4x4 lowp mediump highp precision sampler1D sampler1DShadow
sampler1DArray sampler1DArrayShadow isampler1D isampler1DArray usampler1D usampler1DArray
sampler2D sampler2DShadow sampler2DArray sampler2DArrayShadow isampler2D isampler2DArray
usampler2D usampler2DArray sampler2DRect sampler2DRectShadow isampler2DRect usampler2DRect
sampler2DMS isampler2DMS usampler2DMS sampler2DMSArray isampler2DMSArray usampler2DMSArray
sampler3D isampler3D usampler3D samplerCube samplerCubeShadow isamplerCube usamplerCube
samplerCubeArray samplerCubeArrayShadow isamplerCubeArray usamplerCubeArray samplerBuffer
isamplerBuffer usamplerBuffer image1D iimage1D uimage1D image1DArray iimage1DArray
uimage1DArray image2D iimage2D uimage2D image2DArray iimage2DArray uimage2DArray image2DRect
iimage2DRect uimage2DRect image2DMS iimage2DMS uimage2DMS image2DMSArray iimage2DMSArray
uimage2DMSArray image3D iimage3D uimage3D imageCube iimageCube uimageCube imageCubeArray
iimageCubeArray uimageCubeArray imageBuffer iimageBuffer uimageBuffer struct
common partition active asm class union enum typedef template this resource goto inline
noinline public static extern external interface long short half fixed unsigned superp input
output hvec2 hvec3 hvec4 fvec2 fvec3 fvec4 sampler3DRect filter sizeof cast namespace using
texture1D texture2D texture3D textureCube sampler samplerShadow subroutine
""".split())


def identifier_problem(name: object) -> str | None:
    """Why `name` cannot be a matedit name, or None when it can."""
    if not isinstance(name, str):
        return f"must be a text identifier, got {type(name).__name__}"
    if not name:
        return "must not be empty"
    if len(name) > MAX_NAME:
        return f"is longer than {MAX_NAME} characters"
    if not _ASCII_ID.match(name):
        return ("must be an ASCII identifier (letters A-Z and a-z, digits, '_'; not starting "
                "with a digit)")
    if "__" in name:
        return "must not contain '__' (reserved in GLSL)"
    if name.startswith("gl_"):
        return "must not start with 'gl_' (reserved in GLSL)"
    if name in GLSL_KEYWORDS:
        return "is a GLSL keyword"
    return None


def mangle(text: str, limit: int = 48) -> str:
    """A readable ASCII identifier fragment from any text (for generated names only)."""
    s = re.sub(r"[^A-Za-z0-9]+", "_", text, flags=re.ASCII).strip("_")[:limit].strip("_")
    return s or "x"
