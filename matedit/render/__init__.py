"""moderngl preview renderer: meshes, camera, lights, IBL, program cache (no Qt)."""
