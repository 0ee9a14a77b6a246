"""What the preview shows apart from the material and the mesh: plain attributes that a caller
sets between frames, needing no GL work (the Renderer holds them; the scene pass reads them)."""

from __future__ import annotations

from matedit.render.camera import OrbitCamera
from matedit.render.lights import default_rig
from matedit.shading.lights import Light

MODES = ("splitsum", "reference", "difference")


class PreviewSettings:
    def __init__(self) -> None:
        self.camera = OrbitCamera()
        self.lights: list[Light] = default_rig()  # change through Renderer.set_lights
        self.mode = "splitsum"  # one of MODES
        self.exposure = -0.5  # EV, applied by the display pass
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
