"""The canvas's look in one place: z-orders, sizes, fonts and colours (dark theme).

Port types differ by colour *and* by shape (circle for numbers, diamond for
MaterialAttributes, square for textures), so they read without colour vision too.
"""

from __future__ import annotations

from functools import cache, lru_cache

from PySide6.QtGui import QColor, QFont, QFontMetricsF

# --- z-order (higher draws on top) ---------------------------------------------------------
Z_COMMENT = -10.0
Z_WIRE = -1.0
Z_NODE = 0.0
Z_NODE_SELECTED = 1.0
Z_LIVE_WIRE = 10.0

# --- sizes (scene units; 1 unit = 1 pixel at zoom 1) -----------------------------------------
NODE_MIN_WIDTH = 112.0
NODE_MAX_WIDTH = 260.0
HEADER_HEIGHT = 22.0
SUBTITLE_HEIGHT = 15.0
ROW_HEIGHT = 18.0
BODY_PAD = 5.0
CORNER = 5.0
PORT_RADIUS = 4.5
PORT_HIT_RADIUS = 9.0  # in view pixels: how near the cursor must come to a port
LABEL_GAP = 9.0  # port centre to its label
PREVIEW_SIZE = 64.0
BADGE_RADIUS = 7.0
REROUTE_RADIUS = 7.0
WIRE_WIDTH = 2.0
WIRE_WIDTH_STRUCT = 3.2  # MaterialAttributes wires: the material's backbone
WIRE_HIT_WIDTH = 10.0
COMMENT_HEADER = 26.0
COMMENT_GRIP = 14.0
GRID_MINOR = 20.0
GRID_MAJOR = 100.0

ZOOM_MIN = 0.05
ZOOM_MAX = 3.0
ZOOM_STEP = 1.15
LOD_TEXT = 0.55  # below this zoom nodes draw as coloured blocks under a big title, no labels
LOD_PORTS = 0.3  # below this zoom ports take no clicks (their items hide)
# Zoomed out, a title keeps a constant size on screen: it never drops below LOD_TITLE_MIN_PX
# device pixels in the header, and below LOD_TEXT it fills the whole node body (wrapped),
# starting at LOD_TITLE_PX and shrinking to LOD_TITLE_MIN_PX before it elides.
TITLE_PX = 12  # the title's size at zoom 1 (scene units)
LOD_TITLE_PX = 12.0
LOD_TITLE_MIN_PX = 8.5
LOD_TITLE_NONE = 0.15  # below this zoom a block is too small for any title: none is drawn

SCENE_EXTENT = 100_000.0  # the scene rect: room to pan anywhere

TOAST_MS = 3000

# --- colours ---------------------------------------------------------------------------------
BACKGROUND = QColor("#1b1e24")
GRID_MINOR_COLOR = QColor("#22262e")
GRID_MAJOR_COLOR = QColor("#2b303a")
NODE_BODY = QColor("#2a2e37")
NODE_BODY_EDGE = QColor("#14161a")
BYPASS_VEIL = QColor(18, 20, 24, 165)  # over a bypassed node (its edge dashed too)
NODE_SELECTED = QColor("#f0a64b")
NODE_TEXT = QColor("#e4e7ec")
NODE_SUBTEXT = QColor("#9aa1ae")
PORT_LABEL = QColor("#c4c9d2")
PORT_LABEL_DIM = QColor("#7d8491")  # connected inputs: the value comes from the wire
GROUP_HEADER_FILL = QColor("#323743")  # a pin group's header row (node_item.GroupHeader)
GROUP_HEADER_TEXT = QColor("#aeb6c4")
ERROR = QColor("#e5534b")
WARNING = QColor("#e0a43a")
ALLOWED = QColor("#5ad17a")
REFUSED = QColor("#e5534b")
WIRE_SELECTED = QColor("#ffffff")
TOAST_BG = "#3a2326"
TOAST_FG = "#ffd9d6"
MINIMAP_BG = QColor(20, 22, 27, 215)
MINIMAP_VIEW = QColor("#7aa2f7")

PORT_COLORS: dict[str, QColor] = {
    "float": QColor("#a9b1bd"),  # neutral grey: a plain number
    "vec2": QColor("#4fc3a1"),  # teal
    "vec3": QColor("#f2c94c"),  # yellow: colours and directions
    "vec4": QColor("#c77dde"),  # violet
    "MaterialAttributes": QColor("#5b8cff"),  # blue, drawn thick
    "texture2d": QColor("#f07a4a"),  # orange
    "T": QColor("#e9ecf1"),  # generic, not yet resolved: white outline
}
PORT_SHAPES: dict[str, str] = {
    "MaterialAttributes": "diamond",
    "texture2d": "square",
}

CATEGORY_COLORS: dict[str, QColor] = {
    "Constants": QColor("#4a5261"),
    "Parameters": QColor("#3f6e4c"),
    "Math": QColor("#3d5a80"),
    "Vector": QColor("#4b4f8c"),
    "Utility": QColor("#555b66"),
    "Coordinates": QColor("#7a5a2e"),
    "Texture": QColor("#8a4a34"),
    "Procedural": QColor("#7a3f5e"),
    "Normal": QColor("#6c3f86"),
    "Material": QColor("#2f5f8a"),
    "Layers": QColor("#266f74"),
    "Function": QColor("#6b6b2c"),
    "Output": QColor("#8a2f3a"),
}
CATEGORY_FALLBACK = QColor("#4a4f5a")


def port_color(type_name: str) -> QColor:
    return PORT_COLORS.get(type_name, PORT_COLORS["T"])


def category_color(category: str) -> QColor:
    return CATEGORY_COLORS.get(category, CATEGORY_FALLBACK)


def wire_width(type_name: str) -> float:
    return WIRE_WIDTH_STRUCT if type_name == "MaterialAttributes" else WIRE_WIDTH


# --- fonts (created lazily: they need a QGuiApplication) ------------------------------------
@cache
def title_font(pixel_size: int = TITLE_PX) -> QFont:
    f = QFont("DejaVu Sans")
    f.setPixelSize(pixel_size)
    f.setBold(True)
    return f


@cache
def title_metrics(pixel_size: int) -> QFontMetricsF:
    return QFontMetricsF(title_font(pixel_size))


@cache
def overview_font(pixel_size: int) -> QFont:
    """The zoomed-out title: condensed bold, so more of a name fits a small block."""
    f = QFont("DejaVu Sans")
    f.setPixelSize(pixel_size)
    f.setBold(True)
    f.setStretch(QFont.Stretch.Condensed)
    return f


@cache
def overview_metrics(pixel_size: int) -> QFontMetricsF:
    return QFontMetricsF(overview_font(pixel_size))


def header_title_px(lod: float) -> int:
    """The title's pixel size (scene units) in the header at zoom `lod`: TITLE_PX, grown as
    the view zooms out so it stays LOD_TITLE_MIN_PX on screen, as far as the header allows."""
    want = LOD_TITLE_MIN_PX / max(lod, 1e-6)
    return int(min(max(TITLE_PX, want), HEADER_HEIGHT - 4.0))


def overview_title_px(lod: float) -> tuple[int, int]:
    """The largest and smallest title sizes (scene units) tried on a zoomed-out block, for
    LOD_TITLE_PX and LOD_TITLE_MIN_PX device pixels at zoom `lod`."""
    lod = max(lod, 1e-6)
    return int(round(LOD_TITLE_PX / lod)), int(round(LOD_TITLE_MIN_PX / lod))


@cache
def subtitle_font() -> QFont:
    f = QFont("DejaVu Sans")
    f.setPixelSize(10)
    f.setItalic(True)
    return f


@cache
def port_font() -> QFont:
    f = QFont("DejaVu Sans")
    f.setPixelSize(11)
    return f


@cache
def comment_font() -> QFont:
    f = QFont("DejaVu Sans")
    f.setPixelSize(14)
    f.setBold(True)
    return f


@cache
def metrics(which: str) -> QFontMetricsF:
    font = {"title": title_font, "subtitle": subtitle_font, "port": port_font,
            "comment": comment_font}[which]()
    return QFontMetricsF(font)


@lru_cache(maxsize=8192)
def text_width(which: str, text: str) -> float:
    """The advance of `text` in font `which` (`metrics`' names): node layouts and every paint
    ask for the same few port and title labels again and again, and each answer from Qt
    shapes the text anew."""
    return metrics(which).horizontalAdvance(text)


@lru_cache(maxsize=8192)
def overview_width(pixel_size: int, text: str) -> float:
    """The advance of `text` in the zoomed-out title font of `pixel_size` (as `text_width`)."""
    return overview_metrics(pixel_size).horizontalAdvance(text)
