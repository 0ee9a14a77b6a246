// ATTRIBUTES entry: the raw MaterialAttributes into four float targets (tests, `bake`).
// Leading comment lines are documentation, not emitted.
// MATEDIT_BAKE_VIEW_NORMAL (the bake on a mesh): the eye along the geometric normal of every
// texel, far off, instead of the frame's camera.
void main() {
#ifdef MATEDIT_BAKE_VIEW_NORMAL
    nodeSetupSurface(v_position, v_normal, v_tangent, v_uv,
                     v_position + normalize(v_normal) * 1000.0,
                     uFrame.params.x, uFrame.model, uFrame.viewProjection);
#else
    nodeSetupSurface(v_position, v_normal, v_tangent, v_uv, uFrame.cameraPosition.xyz,
                     uFrame.params.x, uFrame.model, uFrame.viewProjection);
#endif
    MaterialAttributes m = evaluateMaterial();
    out0 = vec4(m.baseColor, m.metallic);
    out1 = vec4(m.normal, m.roughness);
    out2 = vec4(m.emissive, m.cavity);
    out3 = vec4(m.opacity, 0.0, 0.0, 1.0);
}
