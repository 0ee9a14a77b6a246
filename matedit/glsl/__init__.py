"""GLSL source assembly shared by the shading library, the compiler and the bakers."""
