"""Shared fixtures: a headless OpenGL context over EGL, checked for errors after each test."""

from __future__ import annotations

import os
import zlib

import pytest

os.environ.setdefault("MESA_SHADER_CACHE_DISABLE", "false")


@pytest.fixture(scope="session", autouse=True)
def _private_cache(tmp_path_factory):
    """Bakes go to a per-run cache, never the user's."""
    if "MATEDIT_CACHE_DIR" not in os.environ:
        os.environ["MATEDIT_CACHE_DIR"] = str(tmp_path_factory.mktemp("cache"))
    # Recovery files (platformdirs' user data folder) are per run too: parallel runs, and the
    # user's own crashed work, never meet the tests'.
    os.environ["XDG_DATA_HOME"] = str(tmp_path_factory.mktemp("data"))
    # Qt's settings (the editor's remembered view, recent files, export choices) too: under
    # pytest-qt's test mode they would otherwise be ~/.qttest/config, shared by every run.
    from PySide6.QtCore import QSettings

    settings = str(tmp_path_factory.mktemp("settings"))
    for fmt in (QSettings.Format.NativeFormat, QSettings.Format.IniFormat):
        QSettings.setPath(fmt, QSettings.Scope.UserScope, settings)
    os.environ["XDG_CONFIG_HOME"] = settings
    yield


def _release_egl_thread() -> None:
    """Unbinds this thread from EGL. While a thread has an EGL context current, GLVND refuses
    it a GLX one, so Qt's QOpenGLWidget (GLX under Xvfb) could not start in a later test."""
    import ctypes
    import ctypes.util

    name = ctypes.util.find_library("EGL") or "libEGL.so.1"
    try:
        ctypes.CDLL(name).eglReleaseThread()
    except (OSError, AttributeError):  # pragma: no cover - no EGL at all
        pass


def _release_qt_gl() -> None:
    """Makes Qt's current OpenGL context (GLX) not current, so that EGL can be made current:
    GLVND binds a thread to one window-system API at a time, and a refused eglMakeCurrent
    would leave GL calls going to Qt's context."""
    import sys

    if "PySide6.QtGui" not in sys.modules:
        return
    from PySide6.QtGui import QOpenGLContext

    current = QOpenGLContext.currentContext()
    if current is not None:
        current.doneCurrent()


_SESSION_GL: dict = {}


def _collect_qt_garbage() -> None:
    """After a GUI test, on the UI thread: the widgets it closed deleted (deleteLater) and
    the Python wrappers left in reference cycles collected. Otherwise the cyclic collector may
    run next on a worker thread still busy from that test (a cost overlay's `matedit stats`),
    which would delete those widgets off the UI thread while the next test restyles every
    widget (QApplication.setStyle): a segfault seen twice in the suite."""
    import gc

    from PySide6.QtCore import QCoreApplication, QEvent

    if QCoreApplication.instance() is None:
        return
    for _ in range(2):  # a collection can schedule more deleteLater calls
        QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
        gc.collect()


@pytest.fixture(autouse=True)
def _viewport_keeps_its_first_path(request, monkeypatch):
    """GUI tests count links and compare pictures of one path: the viewport's promotion to
    the forward path once idle (Renderer.promote_forward, matedit.render.server) is off for
    them unless a test turns it on (tests/test_app_viewport.py does)."""
    if "qtbot" in request.fixturenames:
        from matedit.app.viewport import ViewportWidget

        monkeypatch.setattr(ViewportWidget, "forward_when_idle", False)
    yield


@pytest.fixture(autouse=True)
def _thread_free_of_egl_for_qt(request):
    """GUI tests get a thread with no EGL context current (Qt's viewport needs GLX there);
    afterwards the headless context is made current again for the GL tests that follow."""
    if "qtbot" not in request.fixturenames:
        yield
        return
    _release_egl_thread()
    yield
    _collect_qt_garbage()
    _release_qt_gl()
    ctx = _SESSION_GL.get("ctx")
    if ctx is not None:
        ctx.__enter__()


@pytest.fixture(scope="session")
def gl_ctx():
    moderngl = pytest.importorskip("moderngl")
    _release_qt_gl()
    try:
        ctx = moderngl.create_standalone_context(require=330, backend="egl")
    except Exception as exc:  # pragma: no cover - depends on the machine
        pytest.fail(f"cannot create a headless EGL context: {exc}")
    _SESSION_GL["ctx"] = ctx
    yield ctx
    _SESSION_GL.clear()
    ctx.release()
    _release_egl_thread()


@pytest.fixture
def ctx(gl_ctx):
    """The session context; fails the test if it leaves a GL error behind."""
    _ = gl_ctx.error  # reading it clears any stale error
    yield gl_ctx
    assert gl_ctx.error == "GL_NO_ERROR"


@pytest.fixture
def rng(request):
    """A random generator seeded by the test's name: stable across runs and processes (str
    hash is salted per process; crc32 is not). A module may define its own."""
    import numpy as np

    return np.random.default_rng(zlib.crc32(request.node.name.encode()))


@pytest.fixture(scope="module")
def render_pair(gl_ctx):
    """A forward and a deferred Renderer, 64 px, 4x MSAA, the studio environment baked small,
    8 reference samples a frame (enough to compare the paths, quick): {"forward", "deferred"}."""
    from matedit.ibl import BakeSettings
    from matedit.render import Renderer

    small = BakeSettings(size=32, samples=64, lut_size=32, lut_samples=1024)
    rs = {name: Renderer(gl_ctx, (64, 64), samples=4, environment="studio", bake_settings=small,
                         deferred=(name == "deferred"))
          for name in ("forward", "deferred")}
    for r in rs.values():
        r.set_reference_samples(8)
    yield rs
    for r in rs.values():
        r.release()
