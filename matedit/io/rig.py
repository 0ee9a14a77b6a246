"""Light rigs as files: the analytic lights of a preview, versioned JSON.

Format (``"format": "matedit.lightrig"``, ``"version": 1``)::

    {
      "format": "matedit.lightrig",
      "version": 1,
      "lights": [
        {"type": "sphere", "position": [2.4, 2.8, 3.0], "radius": 0.3,
         "color": [1.0, 0.96, 0.9], "intensity": 18.0, "influence_radius": 25.0},
        {"type": "tube", "position": [-2.8, 1.6, -2.4], "direction": [0, 1, 0],
         "radius": 0.04, "length": 1.6, "color": [0.75, 0.85, 1.0], "intensity": 10.0},
        {"type": "point", "position": [-3, 0.4, 3], "intensity": 3.0},
        {"type": "directional", "direction": [-0.5, -0.7, -0.5], "intensity": 3.0}
      ]
    }

Fields and units (docs/shading.md#conventions): ``type`` point | directional | sphere |
tube; ``position`` metres, world space (a sphere's or tube's centre; not used by
directional lights); ``direction`` unit vector (normalised on load): the travel direction
of a directional light, a tube's axis; ``radius`` metres (sphere and tube source radius,
>= 0); ``length`` metres (tube, >= 0); ``color`` linear RGB, each >= 0; ``intensity``
>= 0: the radiant intensity of point, sphere and tube lights (radiance scale times the
inverse-square falloff, docs/shading.md#analytic-lights, eq 9), the irradiance of a
directional light; ``influence_radius`` metres (> 0, the falloff window's R). Omitted
fields take the defaults below. At most 16 lights (the shader's block). Unknown fields are
errors (a typo must not pass silently).

Numbers follow the rule of every format (finite, within float32: matedit.graph.numbers) and
stated limits that keep the shader's squares and products finite: positions, radii, lengths
and influence radii within 1e6 m (an influence radius at least 1e-6 m), and intensity times
the brightest colour component at most 1e12. The text follows the JSON rules of documents
(matedit.io.jsontext): no key twice in an object, at most 64 levels of nesting.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

from matedit.graph.numbers import FLOAT32_MAX, describe_number, gpu_number_problem
from matedit.io.atomic import UnsafeFileError, atomic_write_text, read_bounded
from matedit.io.jsontext import JSONTextError, parse_json
from matedit.shading.lights import LIGHT_TYPES, Light

FORMAT = "matedit.lightrig"
VERSION = 1
MAX_RIG_BYTES = 1 << 20
MAX_LIGHTS = 16
# Stated limits, well inside float32, so that what the shader squares and multiplies stays
# finite: lengths (positions, radii, tube lengths, influence radii) in metres, and a light's
# radiance scale (intensity times its brightest colour component).
MAX_EXTENT = 1e6
MIN_INFLUENCE_RADIUS = 1e-6
MAX_LEVEL = 1e12
FIELDS = ("type", "position", "direction", "radius", "length", "color", "intensity",
          "influence_radius", "name")


class RigError(ValueError):
    """A rig file that cannot be read; the message names the file, the light and the field."""

    def __init__(self, file: str | None, message: str, light: int | None = None,
                 field: str | None = None) -> None:
        self.file, self.light, self.field, self.reason = file, light, field, message
        where = []
        if light is not None:
            where.append(f"light {light}")
        if field:
            where.append(f"field {field}")
        loc = (", ".join(where) + ": ") if where else ""
        super().__init__(f"{file or '<rig>'}: {loc}{message}")


def _number(raw, file, i, name, limit: float) -> float:
    """A field under the float32 rule (matedit.graph.numbers) and the rig's stated limit."""
    why = gpu_number_problem(raw)
    if why is None and abs(raw) > limit:
        why = f"value {describe_number(raw)} is beyond the limit of {limit:g}"
    if why:
        raise RigError(file, why, i, name)
    return float(raw)


def _vec3(raw, file, i, name, limit: float = MAX_EXTENT) -> tuple[float, float, float]:
    if not (isinstance(raw, list) and len(raw) == 3):
        raise RigError(file, "must be a list of 3 finite numbers", i, name)
    x, y, z = (_number(v, file, i, name, limit) for v in raw)
    return x, y, z


def _scalar(raw, file, i, name, *, positive=False, limit: float = MAX_EXTENT) -> float:
    value = _number(raw, file, i, name, limit)
    if value < 0 or (positive and value < MIN_INFLUENCE_RADIUS):
        raise RigError(file, f"must be >= {MIN_INFLUENCE_RADIUS:g}" if positive
                       else "must be >= 0", i, name)
    return value


def light_from_dict(raw, file: str | None = None, index: int = 0) -> Light:
    if not isinstance(raw, dict):
        raise RigError(file, "must be an object", index)
    unknown = sorted(set(raw) - set(FIELDS))
    if unknown:
        raise RigError(file, f"unknown field (known: {', '.join(FIELDS)})", index, unknown[0])
    kind = raw.get("type")
    if kind not in LIGHT_TYPES:
        raise RigError(file, f"must be one of {', '.join(LIGHT_TYPES)}, got {kind!r}", index,
                       "type")
    d = Light(kind)
    position = _vec3(raw.get("position", list(d.position)), file, index, "position")
    direction = _vec3(raw.get("direction", [0.0, 1.0, 0.0] if kind == "tube"
                              else list(d.direction)), file, index, "direction", FLOAT32_MAX)
    n = math.sqrt(sum(v * v for v in direction))
    if n < 1e-9:
        raise RigError(file, "must not be the zero vector", index, "direction")
    color = _vec3(raw.get("color", list(d.color)), file, index, "color", MAX_LEVEL)
    if min(color) < 0:
        raise RigError(file, "components must be >= 0", index, "color")
    radius = _scalar(raw.get("radius", 0.0), file, index, "radius")
    length = _scalar(raw.get("length", 0.0), file, index, "length")
    intensity = _scalar(raw.get("intensity", d.intensity), file, index, "intensity",
                        limit=MAX_LEVEL)
    if intensity * max(color) > MAX_LEVEL:  # the light's radiance scale, colour times intensity
        raise RigError(file, f"intensity {intensity:g} times its brightest colour component "
                       f"{max(color):g} is {intensity * max(color):.3g}; at most {MAX_LEVEL:g}",
                       index, "intensity")
    influence = _scalar(raw.get("influence_radius", d.influence_radius), file, index,
                        "influence_radius", positive=True)
    if "name" in raw and not isinstance(raw["name"], str):
        raise RigError(file, "must be a string", index, "name")
    return Light(kind=kind, position=position,
                 direction=(direction[0] / n, direction[1] / n, direction[2] / n), color=color,
                 intensity=intensity, influence_radius=influence,
                 source_radius=radius if kind in ("sphere", "tube") else 0.0,
                 source_length=length if kind == "tube" else 0.0)


def rig_from_dict(raw, file: str | None = None) -> list[Light]:
    if not isinstance(raw, dict):
        raise RigError(file, "a light rig must be a JSON object")
    if raw.get("format") != FORMAT:
        raise RigError(file, f"not a light rig (\"format\" must be {FORMAT!r}, got "
                       f"{raw.get('format')!r})", field="format")
    version = raw.get("version")
    if not (isinstance(version, int) and not isinstance(version, bool)):
        raise RigError(file, "must be an integer", field="version")
    if version > VERSION:
        raise RigError(file, f"version {version} is newer than this matedit reads "
                       f"({VERSION})", field="version")
    if version < 1:
        raise RigError(file, "must be >= 1", field="version")
    unknown = sorted(set(raw) - {"format", "version", "lights"})
    if unknown:
        raise RigError(file, "unknown field", field=unknown[0])
    lights = raw.get("lights")
    if not isinstance(lights, list):
        raise RigError(file, "must be a list of lights", field="lights")
    if len(lights) > MAX_LIGHTS:
        raise RigError(file, f"{len(lights)} lights; at most {MAX_LIGHTS}", field="lights")
    return [light_from_dict(x, file, i) for i, x in enumerate(lights)]


def loads(text: str | bytes, file: str | None = None) -> list[Light]:
    """A rig from its text under the JSON rules every document follows (matedit.io.jsontext:
    no duplicate keys, bounded nesting, 64-bit numbers); raises RigError."""
    try:
        raw = parse_json(text)
    except JSONTextError as exc:
        light = exc.path[1] if len(exc.path) >= 2 and exc.path[0] == "lights" and \
            isinstance(exc.path[1], int) else None
        fld = exc.field
        if light is not None and len(exc.path) >= 3:
            fld = str(exc.path[2])
        elif exc.path and light is None:
            fld = str(exc.path[0])
        raise RigError(file, exc.reason, light, fld) from None
    return rig_from_dict(raw, file)


def load(path: str | os.PathLike) -> list[Light]:
    """Reads a rig file (regular files only, at most 1 MiB); raises RigError."""
    name = str(path)
    try:
        data = read_bounded(path, MAX_RIG_BYTES)
    except FileNotFoundError:
        raise RigError(name, "file not found") from None
    except IsADirectoryError:
        raise RigError(name, "is a directory, not a light rig") from None
    except UnsafeFileError as exc:
        raise RigError(name, str(exc).split(": ", 1)[-1]) from None
    except OSError as exc:
        raise RigError(name, f"cannot read: {exc.strerror or exc}") from None
    return loads(data, name)


def light_to_dict(light: Light) -> dict:
    out: dict = {"type": light.kind, "color": [float(c) for c in light.color],
                 "intensity": float(light.intensity)}
    if light.kind != "directional":
        out["position"] = [float(c) for c in light.position]
        out["influence_radius"] = float(light.influence_radius)
    if light.kind in ("directional", "tube"):
        out["direction"] = [float(c) for c in light.direction]
    if light.kind in ("sphere", "tube"):
        out["radius"] = float(light.source_radius)
    if light.kind == "tube":
        out["length"] = float(light.source_length)
    return out


def dumps(lights: list[Light]) -> str:
    return json.dumps({"format": FORMAT, "version": VERSION,
                       "lights": [light_to_dict(x) for x in lights]}, indent=2) + "\n"


def save(lights: list[Light], path: str | os.PathLike, *, follow_link: bool = False) -> Path:
    """Writes the rig atomically (matedit.io.atomic); a link at `path` is replaced, unless
    `follow_link` (the rig saved back to the name it was loaded from)."""
    if len(lights) > MAX_LIGHTS:
        raise RigError(str(path), f"{len(lights)} lights; at most {MAX_LIGHTS}", field="lights")
    return atomic_write_text(path, dumps(lights), follow_link=follow_link)
