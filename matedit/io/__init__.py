"""File formats: material JSON, and images through OpenImageIO."""
