"""JSON text as every matedit reader takes it: one parser for documents, instances, light
rigs and the small JSON files commands peek at.

`parse_json` refuses, with a `JSONTextError` its caller words for its own format: text that
is not UTF-8, a byte-order mark, NaN/Infinity (not JSON), a key twice in one object, nesting
deeper than MAX_DEPTH arrays and objects, and numbers a 64-bit float cannot hold (1e400
parses to an infinity; a 400-digit integer cannot become a float). Depth is bounded here, so
nothing downstream (schema checks, copies, saves) can recurse without limit, and it is
checked without recursion: the C parser's own RecursionError on 100,000 nested arrays is
caught, and a walk over the parsed value with an explicit stack checks the rest.
"""

from __future__ import annotations

import json
import math
from typing import Any

MAX_DEPTH = 64  # levels of arrays and objects, the top-level value one; real files use < 10
MAX_FLOAT_INT = 2**1023  # larger integers do not round-trip through a 64-bit float


class JSONTextError(ValueError):
    """Why a text is not JSON matedit reads; `field` and `path` (keys and indexes into
    `value`, the parsed JSON when it parsed) locate it when known."""

    def __init__(self, reason: str, field: str | None = None, path: list | None = None) -> None:
        self.reason, self.field, self.path = reason, field, list(path or [])
        self.value: Any = None
        super().__init__(reason)


class _DuplicateKey(ValueError):
    pass


def _object(pairs: list[tuple[str, Any]]) -> dict:
    out: dict[str, Any] = {}
    for k, v in pairs:
        if k in out:
            raise _DuplicateKey(k)
        out[k] = v
    return out


def _no_constants(name: str) -> Any:
    raise ValueError(f"{name} is not valid JSON")


def _check_value(raw: Any) -> None:
    """Depth and 64-bit numbers of a parsed value, with an explicit stack (no recursion)."""
    if _plainly_fine(raw):
        return
    try:
        _walk(raw)
    except JSONTextError as exc:
        exc.value = raw
        raise


def _plainly_fine(raw: Any) -> bool:
    """True when `raw` passes `_walk`, found without its paths: level by level, each of the
    types JSON parses to checked by exact type. False when something fails, nests too deep
    or is of another type (a tuple, a subclass): `_walk` then decides, and words the error."""
    level: list = [raw]
    depth = 0
    while level:
        below: list = []
        for value in level:
            t = type(value)
            if t is dict or t is list:
                if depth >= MAX_DEPTH:
                    return False
                below.extend(value.values() if t is dict else value)
            elif t is float:
                if value - value != 0.0:  # an infinity or NaN (finite: exactly 0.0)
                    return False
            elif t is int:
                if not -MAX_FLOAT_INT <= value <= MAX_FLOAT_INT:
                    return False
            elif t is not str and t is not bool and value is not None:
                return False
        level = below
        depth += 1
    return True


def _walk(raw: Any) -> None:
    stack: list[tuple[Any, list]] = [(raw, [])]
    while stack:
        value, path = stack.pop()
        if isinstance(value, (dict, list)):
            if len(path) >= MAX_DEPTH:
                raise JSONTextError(f"arrays and objects nest more than {MAX_DEPTH} deep",
                                    path=path[:3])  # where it starts, not all 64 steps
            items = value.items() if isinstance(value, dict) else enumerate(value)
            stack.extend((v, [*path, k]) for k, v in items)
        elif isinstance(value, float):
            if not math.isfinite(value):
                raise JSONTextError("number is too large for a 64-bit float", path=path)
        elif isinstance(value, int) and not isinstance(value, bool):
            if abs(value) > MAX_FLOAT_INT:
                raise JSONTextError("integer is too large for a 64-bit float", path=path)


def check_json_value(raw: Any) -> None:
    """The depth and number rules of `parse_json` for a value parsed elsewhere (a dict a
    caller built, the clipboard); raises JSONTextError."""
    _check_value(raw)


def parse_json(text: str | bytes) -> Any:
    """The JSON value of `text` (bytes are read as UTF-8) under the rules above; raises
    JSONTextError and nothing else."""
    if isinstance(text, (bytes, bytearray)):
        try:
            text = bytes(text).decode("utf-8")
        except UnicodeDecodeError:
            raise JSONTextError("not UTF-8 text") from None
    if text.startswith("\ufeff"):
        raise JSONTextError("starts with a UTF-8 byte-order mark; save the file as UTF-8 "
                            "without a BOM")
    try:
        raw = json.loads(text, parse_constant=_no_constants, object_pairs_hook=_object)
    except _DuplicateKey as exc:
        key = str(exc.args[0])
        raise JSONTextError(f"key {key!r} appears twice in one JSON object", field=key) \
            from None
    except RecursionError:
        raise JSONTextError(f"arrays and objects nest more than {MAX_DEPTH} deep") from None
    except ValueError as exc:  # also the digit limit of integers (sys.set_int_max_str_digits)
        raise JSONTextError(f"not valid JSON: {exc}") from None
    _check_value(raw)
    return raw
