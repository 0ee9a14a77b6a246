// ATTRIBUTES entry: the raw MaterialAttributes into four float targets (tests, `bake`).
// Leading comment lines are documentation, not emitted.
void main() {
    g_surface.uv = v_uv;
    g_surface.position = v_position;
    g_surface.normal = normalize(v_normal);
    g_surface.view = normalize(uFrame.cameraPosition.xyz - v_position);
    g_surface.time = uFrame.params.x;
    nodeSurfaceFrame(v_tangent, uFrame.model, uFrame.viewProjection);
    MaterialAttributes m = evaluateMaterial();
    out0 = vec4(m.baseColor, m.metallic);
    out1 = vec4(m.normal, m.roughness);
    out2 = vec4(m.emissive, m.cavity);
    out3 = vec4(m.opacity, 0.0, 0.0, 1.0);
}
