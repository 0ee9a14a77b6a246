"""The one rule for a number a file hands to the GPU: finite and within float32's range.

Material values and settings, parameter defaults and ranges, instance overrides and light-rig
fields all end up in float32 uniforms, vertex attributes or std140 blocks; a value beyond
about 3.4e38 cannot be packed there (Python's struct refuses it, numpy turns it into an
infinity). `gpu_number_problem` says why a value cannot be one, and every format asks it,
so `validate` refuses exactly what the renderer cannot represent.
"""

from __future__ import annotations

import math

FLOAT32_MAX = 3.4028234663852886e38  # numpy.finfo(numpy.float32).max


def describe_number(x: object) -> str:
    """A short spelling of a number for messages (a 400-digit integer is not echoed)."""
    if isinstance(x, int) and not isinstance(x, bool) and abs(x) >= 10**16:
        return f"a {len(str(abs(x)))}-digit integer"
    if isinstance(x, float):
        return repr(x)
    text = repr(x)
    return text if len(text) <= 40 else text[:37] + "..."


def gpu_number_problem(x: object, limit: float = FLOAT32_MAX) -> str | None:
    """Why `x` cannot reach the GPU as a float32 (None when it can): not a number, NaN,
    an infinity, or a magnitude beyond `limit` (float32's largest, unless a caller states
    a tighter bound). Integers of any size are compared exactly, never converted."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return f"expected a number, got {describe_number(x)}"
    if isinstance(x, float) and not math.isfinite(x):
        return f"value {x!r} is not finite"
    if abs(x) > limit:
        if limit == FLOAT32_MAX:
            return (f"value {describe_number(x)} is beyond the float32 range the renderer "
                    f"works in (magnitude at most {FLOAT32_MAX:.7g})")
        return f"value {describe_number(x)} is beyond the stated limit (magnitude at most " \
               f"{limit:g})"
    return None


def gpu_numbers_problem(values: object, count: int | None = None) -> str | None:
    """`gpu_number_problem` for a list of `count` numbers (any length when None)."""
    if not isinstance(values, (list, tuple)) or (count is not None and len(values) != count):
        want = f"a list of {count} numbers" if count is not None else "a list of numbers"
        return f"expected {want}, got {describe_number(values)}"
    for v in values:
        why = gpu_number_problem(v)
        if why:
            return why
    return None
