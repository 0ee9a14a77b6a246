"""The viewport's views, a table with no GL (the editor's tool bar reads it too): the shaded
image with some lobes only (a MATEDIT_LOBES mask of the LOBE_* bits of shaders/surface.glsl),
or one material field drawn in place of the shading (MATEDIT_ATTRIBUTE_VIEW of
shaders/attribute_view.glsl, FORWARD entry only).

`lit` adds no define at all, so its programs are the ones the preview always drew (the same
text and structure hash, the program cache's key).
"""

from __future__ import annotations

from matedit.shading.surface import (
    LOBE_COAT,
    LOBE_DIFFUSE,
    LOBE_SHEEN,
    LOBE_SPECULAR,
    LOBE_SUBSURFACE,
    LOBE_TRANSMISSION,
    LOBES_ALL,
)

# the define of the FORWARD entry's attribute view (matedit.compiler.schedule.ATTRIBUTE_VIEW)
ATTRIBUTE_VIEW = "MATEDIT_ATTRIBUTE_VIEW"
ALL_LOBES = LOBES_ALL
LOBES_DEFINE = "MATEDIT_LOBES"

# view name -> (title, lobe mask or None, attribute view number or None)
VIEWS: dict[str, tuple[str, int | None, int | None]] = {
    "lit": ("Lit", None, None),
    "base": ("Base only", LOBE_DIFFUSE | LOBE_SPECULAR, None),
    "coat": ("Coat only", LOBE_COAT, None),
    "sheen": ("Sheen only", LOBE_SHEEN, None),
    "subsurface": ("Subsurface only", LOBE_SUBSURFACE, None),
    "transmission": ("Transmission only", LOBE_TRANSMISSION, None),
    "specular": ("Specular only", LOBE_SPECULAR | LOBE_COAT, None),
    "roughness": ("Roughness", None, 1),
    "normal": ("Normal", None, 2),
    "coat-weight": ("Coat weight", None, 3),
    "anisotropy": ("Anisotropy direction", None, 4),
    "thin-film": ("Thin film thickness", None, 6),
}
ATTRIBUTE_VIEWS = tuple(v for v, (_, _, a) in VIEWS.items() if a is not None)


def check_view(view: str) -> str:
    if view not in VIEWS:
        raise ValueError(f"unknown view {view!r} (expected {', '.join(VIEWS)})")
    return view


def lobe_mask(view: str) -> int:
    """The LOBE_* mask a view shades with (every lobe for lit and the attribute views)."""
    mask = VIEWS[check_view(view)][1]
    return ALL_LOBES if mask is None else mask


def is_attribute_view(view: str) -> bool:
    return VIEWS[check_view(view)][2] is not None


def view_defines(view: str) -> tuple[str, ...]:
    """The extra defines of a material's FORWARD variant for `view` (none for lit)."""
    _, mask, attribute = VIEWS[check_view(view)]
    if attribute is not None:
        return (f"{ATTRIBUTE_VIEW}={attribute}",)
    if mask is not None:
        return (f"{LOBES_DEFINE}={mask}",)
    return ()
