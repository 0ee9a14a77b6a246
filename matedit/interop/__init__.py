"""Interchange with other tools: the compiled-shader files (`export`), HLSL and MSL through
SPIR-V, baked texture maps, glTF 2.0, MaterialX documents (export and import) and USD
stages (export, `usd`).

Nothing here imports Qt; only `bake` creates a GL context (headless, EGL).
"""
