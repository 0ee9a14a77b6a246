// GBUFFER entry: the preview's deferred material pass. Writes what shadeSurface needs (the
// attributes, the world-space shading normal, the position) to three targets, packed by
// shaders/gbuffer.glsl; the lighting pass (shaders/render/lighting.frag) unpacks and shades
// them. Layout and precision: matedit/render/deferred.py. Leading comment lines are
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
    // position: float32 bits (exact); w: the normal, octahedral
    gbuffer0 = uvec4(floatBitsToUint(g_surface.position), gbufferPackNormal(N));
    gbuffer1 = uvec4(gbufferPackHalf2(m.baseColor.r, m.baseColor.g),
                     gbufferPackHalf2(m.baseColor.b, m.metallic),
                     gbufferPackHalf2(m.emissive.r, m.emissive.g),
                     gbufferPackHalf2(m.emissive.b, m.cavity));
    // roughness, float32 (exact); the coverage, 1 (the float target is cleared to 0: GL leaves
    // a plain clear of an integer target undefined)
    gbuffer2 = vec2(m.roughness, 1.0);
}
