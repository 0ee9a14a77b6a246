"""The deferred lighting pass drawn within the mesh's rectangle only (matedit/render/scene.py
mesh_rect, camera.sphere_screen_bounds): the bound holds every point of the sphere on screen,
is tight, and the frames drawn with it are the frames lit over the whole target, bit for bit
(the rest of the target gets the background the pass wrote there)."""

from __future__ import annotations

import numpy as np
import pytest

from matedit.render.camera import OrbitCamera, sphere_screen_bounds


def _cases(n: int, seed: int = 7):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        cam = OrbitCamera(yaw=rng.uniform(0, 360), pitch=rng.uniform(-80, 80),
                          distance=rng.uniform(0.5, 20), target=tuple(rng.uniform(-1, 1, 3)),
                          fov=rng.uniform(20, 100))
        yield cam, rng.uniform(0.4, 3.0), rng.uniform(-1.5, 1.5, 3), rng.uniform(0.05, 1.5)


def test_the_bound_holds_the_projected_sphere_and_is_tight():
    """Against 20,000 points of each sphere's surface projected by the same matrices: every
    one on screen lies in the rectangle (to 1e-9), and the rectangle's sides are within 5e-3
    of the farthest projected points (sampling leaves that much)."""
    rng = np.random.default_rng(3)
    unit = rng.normal(size=(20000, 3))
    unit /= np.linalg.norm(unit, axis=1)[:, None]
    bounded = unknown = 0
    for cam, aspect, centre, radius in _cases(400):
        view, proj = cam.view_matrix(), cam.projection(aspect)
        b = sphere_screen_bounds(centre, radius, view, proj)
        clip = np.c_[centre + radius * unit, np.ones(len(unit))] @ (proj @ view).T
        if b is None:  # the sphere reaches the near plane: nothing claimed
            unknown += 1
            assert (clip[:, 3] <= cam.near + 1e-9).any() or \
                np.linalg.norm(view[:3, :3] @ centre + view[:3, 3]) <= radius + cam.near
            continue
        assert (clip[:, 3] > 0).all()
        ndc = clip[:, :2] / clip[:, 3:4]
        on = (np.abs(ndc) <= 1.0).all(axis=1)
        x0, y0, x1, y1 = b
        if not on.any():  # off screen: the rectangle may be anything within the screen
            continue
        bounded += 1
        pts = ndc[on]
        assert (pts[:, 0] >= x0 - 1e-9).all() and (pts[:, 0] <= x1 + 1e-9).all()
        assert (pts[:, 1] >= y0 - 1e-9).all() and (pts[:, 1] <= y1 + 1e-9).all()
        lo = np.clip(ndc.min(axis=0), -1, 1)
        hi = np.clip(ndc.max(axis=0), -1, 1)
        assert np.abs(lo - (x0, y0)).max() < 5e-3 and np.abs(hi - (x1, y1)).max() < 5e-3
    assert bounded > 100 and unknown > 5  # both kinds of case were met


def test_an_eye_inside_or_beside_the_sphere_bounds_nothing():
    cam = OrbitCamera(distance=2.0)
    view, proj = cam.view_matrix(), cam.projection(1.0)
    assert sphere_screen_bounds((0, 0, 0), 2.5, view, proj) is None  # the eye inside
    assert sphere_screen_bounds(cam.eye, 0.01, view, proj) is None  # around the eye
    behind = np.asarray(cam.eye) * 1.5  # behind the eye, clear of it
    b = sphere_screen_bounds(behind, 0.1, view, proj)
    assert b is None or b[0] >= b[2] or b[1] >= b[3]


@pytest.mark.parametrize("mesh", ["sphere", "cube", "cylinder", "plane"])
def test_deferred_frames_equal_the_frames_lit_over_the_whole_target(gl_ctx, monkeypatch, mesh):
    """Several framings (default, close up: the whole target, far and off centre, off screen)
    and a frame drawn in bands (reference mode, sliced): the image with the rectangle is the
    image lit everywhere, bit for bit."""
    import matedit.render.scene as scene
    from matedit.compiler import compile_document
    from matedit.ibl import BakeSettings
    from matedit.io.document import FileResolver, load
    from matedit.render import Renderer
    from matedit.resources import graphs_dir

    small = BakeSettings(size=32, samples=64, lut_size=32, lut_samples=1024)
    compiled = compile_document(load(graphs_dir() / "materials" / "worn_painted_steel.json"),
                                FileResolver())
    r = Renderer(gl_ctx, (96, 72), samples=4, environment="studio", bake_settings=small,
                 deferred=True)
    try:
        r.set_mesh(mesh)
        assert r.set_material(compiled).ok
        rect = scene.mesh_rect
        framings = [dict(), dict(distance=0.9), dict(distance=14.0, yaw=80.0, pitch=-30.0,
                                                     target=(1.4, 0.6, 0.0)),
                    dict(target=(30.0, 0.0, 0.0))]
        used = []
        for f in framings:
            r.camera.reset()
            for k, v in f.items():
                setattr(r.camera, k, v)
            images = []
            for whole in (False, True):
                monkeypatch.setattr(scene, "mesh_rect",
                                    (lambda *a: None) if whole else
                                    (lambda *a: used.append(rect(*a)) or used[-1]))
                r.render()
                images.append(np.frombuffer(r.targets.resolved.read(components=4, dtype="f4"),
                                            "f4").copy())
            np.testing.assert_array_equal(images[0], images[1])
        assert any(u is not None and u[2] * u[3] < 96 * 72 for u in used)  # it narrowed
        assert any(u is None for u in used)  # and the close-up lit everything

        # reference mode drawn in bands: the same frames either way
        r.camera.reset()
        r.set_reference_samples(4)
        r.mode = "reference"
        r.slice_budget_ms = 1.0
        frames = []
        for whole in (False, True):
            monkeypatch.setattr(scene, "mesh_rect", (lambda *a: None) if whole else rect)
            r.accumulator.frames = 0
            while r.advance():
                pass
            frames.append(np.frombuffer(r.targets.resolved.read(components=4, dtype="f4"),
                                        "f4").copy())
        np.testing.assert_array_equal(frames[0], frames[1])
    finally:
        r.release()
