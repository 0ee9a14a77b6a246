"""The PySide6 editor application (the only layer that imports Qt)."""
