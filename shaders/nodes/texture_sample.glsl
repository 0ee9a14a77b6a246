// Texture Sample node: one filtered read of a texture, and its channels.
// Filtering and wrapping are the sampler's (the renderer binds GL_LINEAR, GL_REPEAT).

void node_texture_sample(sampler2D tex, vec2 uv, out vec4 rgba, out vec3 rgb, out float r,
                         out float g, out float b, out float a) {
    // GLSL texture(): bilinear between the four nearest texel centres (i + 0.5) / size
    rgba = texture(tex, uv);
    rgb = rgba.rgb;
    r = rgba.r;
    g = rgba.g;
    b = rgba.b;
    a = rgba.a;
}
