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
