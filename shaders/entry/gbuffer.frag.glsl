// GBUFFER entry: the preview's deferred material pass. Writes what shadeSurface needs (the
// attributes, the world-space shading normal, the position) to four float targets; the
// lighting pass (shaders/render/lighting.frag) shades them. Leading comment lines are
// documentation, not emitted.
void main() {
    vec3 Ng = normalize(v_normal);
    if (!gl_FrontFacing) Ng = -Ng;
    vec3 V = normalize(uFrame.cameraPosition.xyz - v_position);
    g_surface.uv = v_uv;
    g_surface.position = v_position;
    g_surface.normal = Ng;
    g_surface.view = V;
    g_surface.time = uFrame.params.x;
    nodeSurfaceFrame(v_tangent, uFrame.model, uFrame.viewProjection);
    MaterialAttributes m = evaluateMaterial();
    vec3 N = Ng;
#ifdef MATERIAL_HAS_NORMAL
    vec3 T = normalize(v_tangent.xyz - Ng * dot(Ng, v_tangent.xyz));
    vec3 B = cross(Ng, T) * (v_tangent.w < 0.0 ? -1.0 : 1.0);
    N = tangentToWorldNormal(m.normal, T, B, Ng);
#endif
    // layout: matedit.render.gbuffer.GBUFFER_LAYOUT (float32, values kept exactly)
    gbuffer0 = vec4(m.baseColor, m.metallic);
    gbuffer1 = vec4(N, m.roughness);
    gbuffer2 = vec4(m.emissive, m.cavity);
    gbuffer3 = vec4(v_position, 1.0);  // w: coverage (cleared to 0)
}
