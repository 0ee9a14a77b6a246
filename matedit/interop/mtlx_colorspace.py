"""Texture colour spaces between matedit and MaterialX 1.39.

matedit names a texture's space `srgb`, `linear` or an OpenColorIO space of OpenImageIO's
built-in config (matedit.shading.colorspace). MaterialX names the spaces of its colour
management library (cmlib): `srgb_texture`, `lin_rec709` (the working space of our documents),
`acescg`, `g22_rec709`, `lin_displayp3`, ... The OpenColorIO config lists MaterialX's names
among its aliases (`sRGB Encoded Rec.709 (sRGB)` is also `srgb_texture`), so the two are
matched through them, never by a table of our own.

MaterialX converts only colour-typed values (color3/color4): an image read in another space
than the document's must be a color3/color4 image for its decoding to happen.
"""

from __future__ import annotations

import functools

from matedit.shading.colorspace import LINEAR, SRGB, check_space

WORKING = "lin_rec709"  # MaterialX's name for linear Rec.709, what matedit shades in
SRGB_TEXTURE = "srgb_texture"


@functools.lru_cache(maxsize=1)
def stdlib():
    """MaterialX's standard libraries, loaded once (read only)."""
    import MaterialX as mx

    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    return lib


@functools.lru_cache(maxsize=1)
def materialx_spaces() -> frozenset[str]:
    """The colour spaces MaterialX's cmlib converts to lin_rec709, and lin_rec709 itself."""
    suffix = f"_to_{WORKING}_color3"
    names = {WORKING}
    for nd in stdlib().getNodeDefs():
        name = nd.getName()
        if name.startswith("ND_") and name.endswith(suffix):
            names.add(name[3:-len(suffix)])
    return frozenset(names)


def _aliases(space: str) -> list[str]:
    import OpenImageIO as oiio

    config = oiio.ColorConfig()
    return [space, *config.getAliases(space)]


def to_materialx(space: str) -> str | None:
    """The MaterialX name of a matedit colour space (already checked), or None when MaterialX
    1.39 has no equivalent."""
    space = check_space(space)
    if space == SRGB:
        return SRGB_TEXTURE
    if space == LINEAR or space == "Raw":
        return WORKING
    known = {n.lower(): n for n in materialx_spaces()}
    for alias in _aliases(space):
        if alias.lower() in known:
            return known[alias.lower()]
    return None


def from_materialx(name: str) -> tuple[bool, str] | None:
    """(srgb flag, color_space setting) of a texture parameter for a MaterialX colour space,
    or None when OpenColorIO's config knows no such space."""
    from matedit.shading.colorspace import ocio_spaces

    low = name.strip().lower()
    if low in ("", WORKING):
        return (False, "")
    if low == SRGB_TEXTURE:
        return (True, "")
    for space in ocio_spaces():
        if low in (a.lower() for a in _aliases(space)):
            return (False, space)
    return None
