"""The user's folders for matedit: cache, configuration and crash recovery.

They come from `platformdirs` (XDG on Linux: ``$XDG_CACHE_HOME/matedit``,
``$XDG_CONFIG_HOME/matedit``, ``$XDG_DATA_HOME/matedit/recovery``; the platform's
own places elsewhere). ``MATEDIT_CACHE_DIR`` overrides the cache folder, so tests and
build machines can keep bakes out of the user's home. Nothing here creates a folder:
whoever writes into one creates it.
"""

from __future__ import annotations

import os
from pathlib import Path

import platformdirs

APP = "matedit"
CACHE_ENV = "MATEDIT_CACHE_DIR"


def cache_dir() -> Path:
    """Where bakes and other re-computable files go (``MATEDIT_CACHE_DIR`` overrides)."""
    override = os.environ.get(CACHE_ENV)
    if override:
        return Path(override).expanduser()
    return platformdirs.user_cache_path(APP, appauthor=False)


def config_dir() -> Path:
    """Where settings go."""
    return platformdirs.user_config_path(APP, appauthor=False)


def recovery_dir() -> Path:
    """Where autosaved copies of unsaved work wait to be offered back after a crash."""
    return platformdirs.user_data_path(APP, appauthor=False) / "recovery"
