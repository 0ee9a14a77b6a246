"""moderngl preview renderer: meshes, camera, lights, IBL, program cache (no Qt)."""

from matedit.render.camera import OrbitCamera
from matedit.render.mesh import BUILTIN_MESHES, MeshError
from matedit.render.renderer import MODES, MaterialStatus, Renderer

__all__ = ["BUILTIN_MESHES", "MODES", "MaterialStatus", "MeshError", "OrbitCamera", "Renderer"]
