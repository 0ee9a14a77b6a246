"""Image-based lighting bakes."""
