// FORWARD entry: the material's attributes shaded by shadeSurface in one shader (what
// `matedit compile` exports). Leading comment lines are documentation, not emitted.
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
    fragColor = vec4(shadeSurface(m, v_position, N, V), clamp(m.opacity, 0.0, 1.0));
}
