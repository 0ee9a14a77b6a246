// What geometry nodes read about the surface point being shaded. The generated main()
// fills g_surface before any graph code runs; node functions only read it.

struct SurfaceContext {
    vec2 uv;        // mesh UV set 0
    vec3 position;  // world space, metres
    vec3 normal;    // world-space geometric normal (before normal maps), unit length
    vec3 view;      // unit vector from the surface towards the eye, world space
    float time;     // seconds since the preview started
    vec4 tangent;   // world-space mesh tangent (xyz) and handedness (w), not orthogonalised
    mat4 model;     // object to world (zero when the pass has no transform: read as identity)
    mat4 viewProjection;  // world to clip (zero when the pass has no camera)
};

SurfaceContext g_surface;

// Stores the frame the space nodes read (called by the generated main()).
void nodeSurfaceFrame(vec4 tangent, mat4 model, mat4 viewProjection) {
    // Plain copies: the nodes that need a basis or an inverse derive it themselves
    g_surface.tangent = tangent;
    g_surface.model = model;
    g_surface.viewProjection = viewProjection;
}

// Fills g_surface from the interpolated vertex data: the first call of every entry's main().
// `normal` is the interpolated geometric normal (the entries that shade pass it facing the
// eye's side), renormalised here.
void nodeSetupSurface(vec3 position, vec3 normal, vec4 tangent, vec2 uv, vec3 eye, float time,
                      mat4 model, mat4 viewProjection) {
    // matedit entry points: one setup shared by the forward, G-buffer and attributes entries
    g_surface.uv = uv;
    g_surface.position = position;
    g_surface.normal = normalize(normal);
    g_surface.view = normalize(eye - position);
    g_surface.time = time;
    nodeSurfaceFrame(tangent, model, viewProjection);
}

// The orthonormal tangent frame of the shaded point: the mesh tangent made orthogonal to the
// geometric normal (Gram-Schmidt), the bitangent N x T with the tangent's handedness.
void nodeTangentFrame(out vec3 T, out vec3 B) {
    // Mikkelsen 2008, "Simulation of Wrinkled Surfaces Revisited": B = sign(w) (N x T)
    vec3 Ng = g_surface.normal;
    T = normalize(g_surface.tangent.xyz - Ng * dot(Ng, g_surface.tangent.xyz));
    B = cross(Ng, T) * (g_surface.tangent.w < 0.0 ? -1.0 : 1.0);
}
