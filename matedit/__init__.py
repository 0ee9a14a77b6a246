"""matedit: a node-based material layering editor (Karis 2013 shading model)."""

__version__ = "0.1.0"
