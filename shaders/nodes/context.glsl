// What geometry nodes read about the surface point being shaded. The generated main()
// fills g_surface before any graph code runs; node functions only read it.

struct SurfaceContext {
    vec2 uv;        // mesh UV set 0
    vec3 position;  // world space, metres
    vec3 normal;    // world-space geometric normal (before normal maps), unit length
    vec3 view;      // unit vector from the surface towards the eye, world space
    float time;     // seconds since the preview started
};

SurfaceContext g_surface;
