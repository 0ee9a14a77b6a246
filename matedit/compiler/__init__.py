"""Graph to GLSL: typed IR, optimisation, emission per target, reflection, CPU evaluator."""
