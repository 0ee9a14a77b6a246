"""Port types and the implicit conversions between them.

A float splats to any vector; nothing else converts silently. `T` in a node
definition is a generic float-or-vector type resolved per node from what is
connected (see `matedit.graph.nodes`).
"""

from __future__ import annotations

from enum import Enum

from matedit.graph.numbers import FLOAT32_MAX, gpu_number_problem


class PortType(str, Enum):
    FLOAT = "float"
    VEC2 = "vec2"
    VEC3 = "vec3"
    VEC4 = "vec4"
    MATERIAL = "MaterialAttributes"
    TEXTURE = "texture2d"

    def __str__(self) -> str:
        return self.value

    # Looked up by value: a str hashes once and caches it, an Enum member hashes in Python.
    @property
    def components(self) -> int:
        """Number of float components (0 for the struct and textures)."""
        return _COMPONENTS[self._value_]

    @property
    def is_numeric(self) -> bool:
        return _COMPONENTS[self._value_] > 0


_COMPONENTS = {"float": 1, "vec2": 2, "vec3": 3, "vec4": 4, "MaterialAttributes": 0,
               "texture2d": 0}
NUMERIC = (PortType.FLOAT, PortType.VEC2, PortType.VEC3, PortType.VEC4)


def parse_type(name: str) -> PortType:
    """A PortType from its file spelling; ValueError naming the choices otherwise."""
    try:
        return PortType(name)
    except ValueError:
        choices = ", ".join(t.value for t in PortType)
        raise ValueError(f"unknown type {name!r} (expected one of {choices})") from None


def can_convert(src: PortType, dst: PortType) -> bool:
    """Whether a value of type `src` may flow into a port of type `dst` without a node."""
    return src == dst or (src == PortType.FLOAT and dst in NUMERIC)


def conversion_reason(src: PortType, dst: PortType) -> str | None:
    """None when the link is allowed, else a sentence an artist can act on."""
    if can_convert(src, dst):
        return None
    if src.is_numeric and dst.is_numeric:
        return (
            f"cannot connect {src} to {dst}: only a float converts implicitly; "
            f"use a Component Mask or Append node"
        )
    return f"cannot connect {src} to {dst}"


def coerce_value(t: PortType, value: object) -> float | list[float]:
    """Check and normalise a stored value for a numeric port; a number splats to a vector.

    Raises ValueError with a short reason; callers add the file, node and field.
    """
    n = _COMPONENTS[t._value_]
    if type(value) is float and n and -FLOAT32_MAX <= value <= FLOAT32_MAX:
        # the common case, the rest's answer at once: a finite float in float32's range (NaN
        # fails both comparisons and takes the path below, which words its error)
        return value if n == 1 else [value] * n
    if n == 0:
        raise ValueError(f"a {t} port holds no value")
    if isinstance(value, bool) or value is None:
        raise ValueError(f"expected a number or {n} numbers, got {value!r}")
    if isinstance(value, (int, float)):
        _check_gpu_number(value)
        v = float(value)
        return v if n == 1 else [v] * n
    if isinstance(value, (list, tuple)):
        if len(value) != n or not all(
            isinstance(x, (int, float)) and not isinstance(x, bool) for x in value
        ):
            raise ValueError(f"expected {n} numbers for {t}, got {value!r}")
        for x in value:
            _check_gpu_number(x)
        vals = [float(x) for x in value]
        return vals[0] if n == 1 else vals
    raise ValueError(f"expected a number or {n} numbers, got {type(value).__name__}")


def _check_gpu_number(v: int | float) -> None:
    """Refuse what a float32 uniform cannot hold (matedit.graph.numbers, the one rule)."""
    why = gpu_number_problem(v)
    if why:
        raise ValueError(why)
