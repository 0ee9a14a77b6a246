"""A guard against a reference-count bug of PySide6 6.12.0 on Python < 3.12.

shiboken6 6.12.0 treats None, True and False as immortal, as they are from Python
3.12 on (PEP 683): it hands them out, and releases them after calls into Python
(slots, event filters, virtual overrides), without balancing their reference
counts. On 3.10 and 3.11 each void call (`painter.setPen`, `item.setPos`, ...) and
each bool from a Python override drops a count by one, and after a few thousand
the interpreter aborts ("none_dealloc: deallocating None", "bool_dealloc"). One
repaint of a big canvas makes thousands of such calls.

Until the project pins a PySide6 without the bug (6.11.2 is fine), give those
singletons counts no run can exhaust: what Python 3.12 does by making them immortal.
"""

from __future__ import annotations

import ctypes
import sys

import PySide6

_HEADROOM = 1 << 48


def _needs_guard() -> bool:
    return sys.version_info < (3, 12) and PySide6.__version__.startswith("6.12.")


def guard_none_refcount() -> bool:
    """Raise the singletons' reference counts out of reach once; True if applied."""
    if not _needs_guard():
        return False
    for singleton in (None, True, False, Ellipsis, NotImplemented):
        # ob_refcnt is the first field of every PyObject in CPython < 3.12.
        count = ctypes.c_ssize_t.from_address(id(singleton))
        if count.value < _HEADROOM:
            count.value += _HEADROOM
    return True
