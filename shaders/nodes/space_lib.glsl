// Shared space helpers (not a node kind): the tangent frame and the object and view
// transforms of the surface point, from what the generated main() stored in g_surface.
#include "context.glsl"

vec3 nodeSurfaceTangent() {
    // Gram-Schmidt: the mesh tangent made orthogonal to the normal; a fixed perpendicular
    // where the mesh has none
    vec3 n = g_surface.normal;
    vec3 t = g_surface.tangent.xyz - n * dot(n, g_surface.tangent.xyz);
    if (dot(t, t) < 1e-12) {
        vec3 a = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
        t = a - n * dot(n, a);
    }
    return t * inversesqrt(dot(t, t));
}

vec3 nodeSurfaceBitangent() {
    // Mikkelsen 2008: B = sign * (N x T)
    return cross(g_surface.normal, nodeSurfaceTangent()) * (g_surface.tangent.w < 0.0 ? -1.0
                                                                                       : 1.0);
}

mat4 nodeWorldToObject() {
    // The inverse model matrix; identity where it is singular (no transform given)
    mat4 m = g_surface.model;
    return abs(determinant(m)) > 1e-12 ? inverse(m) : mat4(1.0);
}

mat3 nodeObjectToWorld() {
    // The model matrix's linear part; identity where it is singular
    mat4 m = g_surface.model;
    return abs(determinant(m)) > 1e-12 ? mat3(m) : mat3(1.0);
}

mat3 nodeWorldToView() {
    // The camera rotation recovered from the view-projection matrix of a symmetric
    // frustum: its rows x and y are the view axes scaled, and -w (perspective) or -z
    // (orthographic) is the view z axis; identity when the matrix is degenerate
    mat4 m = g_surface.viewProjection;
    vec3 r0 = vec3(m[0][0], m[1][0], m[2][0]);
    vec3 r1 = vec3(m[0][1], m[1][1], m[2][1]);
    vec3 r2 = vec3(m[0][2], m[1][2], m[2][2]);
    vec3 r3 = vec3(m[0][3], m[1][3], m[2][3]);
    vec3 z = dot(r3, r3) > 1e-12 ? -r3 : -r2;
    if (dot(r0, r0) < 1e-12 || dot(r1, r1) < 1e-12 || dot(z, z) < 1e-12) {
        return mat3(1.0);
    }
    return transpose(mat3(normalize(r0), normalize(r1), normalize(z)));
}
