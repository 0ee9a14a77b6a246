// Addressed Texture Sample node: MaterialX image's address modes and filter types, in the
// shader, over the renderer's sampler (GL_LINEAR, GL_REPEAT, no mipmaps). MaterialX's GLSL
// renderer binds them as sampler state: periodic GL_REPEAT, clamp GL_CLAMP_TO_EDGE, mirror
// GL_MIRRORED_REPEAT, constant GL_CLAMP_TO_BORDER with the default as border colour;
// closest GL_NEAREST. Each is one read here:
//   clamp    the coordinate clamped to the edge texels' centres (no weight on a wrapped
//            neighbour is left);
//   mirror   the coordinate reflected at every integer, then clamped so (at the seam the
//            mirrored neighbour is the edge texel itself);
//   constant clamped so, then blended towards the default by the weight the border texels
//            would have: clamp(0.5 + min(t, 1 - t) * size, 0, 1) per axis, their product;
//   closest  the addressed coordinate moved to its texel's centre.

float node_address_axis(float t, float mode, float n) {
    // the coordinate to read along one axis of n texels (the table above)
    if (mode < 0.5) {
        return t;
    }
    float m = mode > 1.5 && mode < 2.5 ? 1.0 - abs(mod(t, 2.0) - 1.0) : t;
    return clamp(m, 0.5 / n, 1.0 - 0.5 / n);
}

float node_address_weight(float t, float mode, float n, bool closest) {
    // the weight of the image against the border colour along one axis (constant only)
    if (mode < 2.5) {
        return 1.0;
    }
    return closest ? (t >= 0.0 && t < 1.0 ? 1.0 : 0.0)
                   : clamp(0.5 + min(t, 1.0 - t) * n, 0.0, 1.0);
}

void node_texture_sample_addressed(sampler2D tex, vec2 uv, vec4 default_value,
                                   float u_address, float v_address, float filter_type,
                                   out vec4 rgba, out vec3 rgb, out float r, out float g,
                                   out float b, out float a) {
    // GL sampler semantics (OpenGL 4.6 section 8.14.2) in one bilinear read
    vec2 n = vec2(textureSize(tex, 0));
    vec2 mode = floor(clamp(vec2(u_address, v_address), 0.0, 3.0) + 0.5);
    bool closest = filter_type >= 0.5;
    vec2 st = vec2(node_address_axis(uv.x, mode.x, n.x), node_address_axis(uv.y, mode.y, n.y));
    if (closest) {
        vec2 texel = floor(st * n);
        // periodic: the sampler wraps the texel; the others stay on the image
        texel = mix(min(texel, n - 1.0), texel, vec2(lessThan(mode, vec2(0.5))));
        st = (texel + 0.5) / n;
    }
    float w = node_address_weight(uv.x, mode.x, n.x, closest)
            * node_address_weight(uv.y, mode.y, n.y, closest);
    rgba = mix(default_value, texture(tex, st), w);
    rgb = rgba.rgb;
    r = rgba.r;
    g = rgba.g;
    b = rgba.b;
    a = rgba.a;
}
