// FORWARD entry: the material's attributes shaded by shadeSurface in one shader (what
// `matedit compile` exports). Leading comment lines are documentation, not emitted.
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
#ifdef MATEDIT_ATTRIBUTE_VIEW
    // The viewport's attribute view (preview only: the block is left out of the text
    // unless asked for): a field drawn in place of the shading, opaque.
    fragColor = vec4(attributeView(MATEDIT_ATTRIBUTE_VIEW, m, g_surface.uv, N), 1.0);
#else
    fragColor = vec4(shadeSurface(m, g_surface.position, N, g_surface.view, g_surface.normal,
                                  T, B), clamp(m.opacity, 0.0, 1.0));
#endif
}
