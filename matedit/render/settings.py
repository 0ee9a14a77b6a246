"""What the preview shows apart from the material and the mesh: plain attributes that a caller
sets between frames, needing no GL work (the Renderer holds them; the scene pass reads them)."""

from __future__ import annotations

import math

from matedit.render.camera import OrbitCamera
from matedit.render.lights import default_rig
from matedit.shading.lights import Light

MODES = ("splitsum", "reference", "difference")
# 0 EV: the scene's radiance as it is, what the editor's viewport starts at and what
# `matedit render` applies without --exposure (docs/cli.md).
DEFAULT_EXPOSURE_EV = 0.0
# Exposures beyond +-30 EV (a factor of about 1e9) are no use for a preview and bring the
# display pass near float32's limits; `render --exposure` refuses them.
EXPOSURE_LIMIT_EV = 30.0


def exposure_problem(ev: float) -> str | None:
    """Why `ev` cannot be an exposure (None when it can): NaN, infinite or beyond +-30 EV."""
    if not math.isfinite(ev):
        return f"exposure must be a finite number of stops, got {ev!r}"
    if abs(ev) > EXPOSURE_LIMIT_EV:
        return (f"exposure must be within -{EXPOSURE_LIMIT_EV:g}..{EXPOSURE_LIMIT_EV:g} EV, "
                f"got {ev:g}")
    return None


class PreviewSettings:
    def __init__(self) -> None:
        self.camera = OrbitCamera()
        self.lights: list[Light] = default_rig()  # change through Renderer.set_lights
        self.mode = "splitsum"  # one of MODES
        self.exposure = DEFAULT_EXPOSURE_EV  # EV, applied by the display pass
        self.time = 0.0  # seconds, FrameBlock params.x
        self.show_background = True
        self.background_blur = 0.0  # 0 (sharp) to 1 (the roughest prefiltered mip)
        self.show_gizmos = True
        self.environment_intensity = 1.0
        self.reference_samples = 32  # per pixel per frame
        self.reference_frames = 64  # frames to converge (32 x 64 = 2048 samples a pixel)
        # reference mode integrates sphere and tube lights by Monte Carlo over their shapes
        self.reference_lights = True
        # multiple-scattering compensation in every material (beyond the talk; off), on top
        # of materials that ask for it themselves (preview "energy_compensation": true);
        # change through Renderer.set_energy_compensation
        self.energy_compensation = False
        # the viewport's view (matedit.shading.views): lit, a lobe view or an attribute view;
        # change through Renderer.set_view
        self.view = "lit"
