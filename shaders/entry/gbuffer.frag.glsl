// GBUFFER entry: the preview's deferred material pass. Writes what shadeSurface needs (the
// attributes, the world-space shading normal, the position) to four float targets; the
// lighting pass (shaders/render/lighting.frag) shades them. Leading comment lines are
// documentation, not emitted.
void main() {
    nodeSetupSurface(v_position, gl_FrontFacing ? v_normal : -v_normal, v_tangent, v_uv,
                     uFrame.cameraPosition.xyz, uFrame.params.x, uFrame.model,
                     uFrame.viewProjection);
    MaterialAttributes m = evaluateMaterial();
    vec3 T, B;
    nodeTangentFrame(T, B);
    vec3 N = g_surface.normal;
#ifdef MATERIAL_HAS_NORMAL
    N = tangentToWorldNormal(m.normal, T, B, g_surface.normal);
#endif
    // layout: matedit/render/deferred.py (float32, values kept exactly)
    gbuffer0 = vec4(m.baseColor, m.metallic);
    gbuffer1 = vec4(N, m.roughness);
    gbuffer2 = vec4(m.emissive, m.cavity);
    gbuffer3 = vec4(g_surface.position, 1.0);  // w: coverage (cleared to 0)
}
