"""Start-up: the window's first frame comes before the environment's bake (or cache load) and
before the Library reads its folders; both follow it (real GL under Xvfb)."""

from __future__ import annotations

import pytest
from graphs_util import EDITOR_SAMPLE
from test_app_support import app_env, make_window  # noqa: F401

pytestmark = [pytest.mark.gui, pytest.mark.usefixtures("app_env")]


def test_the_first_frame_comes_before_the_environment_and_the_library(qtbot):
    w = make_window(qtbot, EDITOR_SAMPLE)
    assert not w.library.listed and w.library.tree.topLevelItemCount() == 0
    view = w.viewport.view
    seen: list[tuple[str, bool, bool]] = []
    view.frameDrawn.connect(lambda: seen.append(
        (view.frame_info.environment_name, view.environment_ready, w.library.listed)))
    w.resize(1400, 880)
    w.show()
    qtbot.waitUntil(lambda: (view.environment_ready and w.library.listed) or bool(view.problem),
                    timeout=120000)
    assert not view.problem, view.problem
    n = view.frames
    view.update()
    qtbot.waitUntil(lambda: view.frames > n, timeout=10000)
    # the first frame: no environment yet (the lights alone), the Library not read
    assert seen[0] == ("", False, False)
    assert seen[-1][:2] == ("studio", True)  # then the environment the view was set to
    assert view.renderer.environment_name == "studio"
    # the sample material on the deferred path (or drawn forward since, the viewport idle:
    # Renderer.promote_forward)
    assert view.renderer.has_material
    assert not view.renderer.is_forward or view.renderer.promoted
    assert w.library.items("material") and w.library.items("layer")


def test_the_library_lists_at_once_when_asked_and_after_a_while_without_frames(qtbot):
    from matedit.app.startup import FALLBACK_MS

    w = make_window(qtbot, EDITOR_SAMPLE)  # never shown: no GL, no frame
    assert not w.library.listed
    qtbot.waitUntil(lambda: w.library.listed, timeout=FALLBACK_MS + 10000)
    assert w.library.files and w.library.items("function")
    other = make_window(qtbot, EDITOR_SAMPLE)
    assert other.library.items("material")  # asked: read now
    assert other.library.listed
