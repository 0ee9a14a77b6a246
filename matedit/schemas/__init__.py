"""JSON Schema files of the matedit document formats (package data)."""
