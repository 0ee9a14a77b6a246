"""Shared fixtures: a headless OpenGL context over EGL, checked for errors after each test."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "false")


@pytest.fixture(scope="session", autouse=True)
def _private_cache(tmp_path_factory):
    """Bakes go to a per-run cache, never the user's."""
    if "MATEDIT_CACHE_DIR" not in os.environ:
        os.environ["MATEDIT_CACHE_DIR"] = str(tmp_path_factory.mktemp("cache"))
    yield


@pytest.fixture(scope="session")
def gl_ctx():
    moderngl = pytest.importorskip("moderngl")
    try:
        ctx = moderngl.create_standalone_context(require=330, backend="egl")
    except Exception as exc:  # pragma: no cover - depends on the machine
        pytest.fail(f"cannot create a headless EGL context: {exc}")
    yield ctx
    ctx.release()


@pytest.fixture
def ctx(gl_ctx):
    """The session context; fails the test if it leaves a GL error behind."""
    _ = gl_ctx.error  # reading it clears any stale error
    yield gl_ctx
    assert gl_ctx.error == "GL_NO_ERROR"
