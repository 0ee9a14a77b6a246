// Blend Normals node: a detail normal applied on a base normal, both unit tangent-space
// vectors, by reoriented normal mapping: the detail is rotated by the rotation that takes
// (0, 0, 1) to the base.
#include "normal_math.glsl"

void node_blend_normals(vec3 base, vec3 detail, out vec3 normal) {
    // Barré-Brisebois & Hill 2012, "Blending in Detail": RNM on unpacked normals,
    // t = base + (0,0,1), u = detail * (-1,-1,1), r = t dot(t, u) / t.z - u
    vec3 t = base + vec3(0.0, 0.0, 1.0);
    vec3 u = detail * vec3(-1.0, -1.0, 1.0);
    vec3 r = t * dot(t, u) / t.z - u;
    normal = nodeSafeNormalize(r, vec3(0.0, 0.0, 1.0));
}
