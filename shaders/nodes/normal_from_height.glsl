// Normal from Height node: bump mapping from screen-space derivatives.
#include "context.glsl"

void node_normal_from_height(float height, float strength, out vec3 normal) {
    // Mikkelsen 2010, "Bump Mapping Unparametrized Surfaces on the GPU", in UV space: the
    // height's screen derivatives solved through the UV Jacobian give dh/du and dh/dv;
    // the tangent-space normal is (-s dh/du, -s dh/dv, 1) normalised
    vec2 duvdx = dFdx(g_surface.uv);
    vec2 duvdy = dFdy(g_surface.uv);
    float dhdx = dFdx(height);
    float dhdy = dFdy(height);
    float det = duvdx.x * duvdy.y - duvdx.y * duvdy.x;
    vec2 g = vec2(0.0);
    if (abs(det) > 1e-20) {
        g = vec2(dhdx * duvdy.y - dhdy * duvdx.y, dhdy * duvdx.x - dhdx * duvdy.x) / det;
    }
    vec3 n = vec3(-strength * g, 1.0);
    normal = n * inversesqrt(dot(n, n));
}
