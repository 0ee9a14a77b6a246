// ATTRIBUTES entry: the raw MaterialAttributes into four float targets (tests, `bake`).
// Leading comment lines are documentation, not emitted.
void main() {
    nodeSetupSurface(v_position, v_normal, v_tangent, v_uv, uFrame.cameraPosition.xyz,
                     uFrame.params.x, uFrame.model, uFrame.viewProjection);
    MaterialAttributes m = evaluateMaterial();
    out0 = vec4(m.baseColor, m.metallic);
    out1 = vec4(m.normal, m.roughness);
    out2 = vec4(m.emissive, m.cavity);
    out3 = vec4(m.opacity, 0.0, 0.0, 1.0);
}
