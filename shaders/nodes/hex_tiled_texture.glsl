// Hex-Tiled Texture node: Mikkelsen, "Practical Real-Time Hex-Tiling" (JCGT 11(2), 2022),
// with MaterialX hextiledimage's parameters: a triangle grid whose vertices are the centres
// of hexagonal tiles, each with its own random rotation, scale and offset; every point reads
// the three tiles of its triangle and blends them by luminance and barycentric weight.
// The renderer's sampler has no mipmaps, so each read is a plain texture() (the level-0
// read textureGrad gives then).

vec2 node_hex_hash(vec2 p) {
    // Dave Hoskins' "hash without sine" (two outputs from two inputs)
    vec3 p3 = fract(vec3(p.x, p.y, p.x) * vec3(0.1031, 0.1030, 0.0973));
    p3 += dot(p3, p3.yzx + 33.33);
    return fract((p3.xx + p3.yz) * p3.zy);
}

float node_hex_gain(float x, float r) {
    // Schlick's gain (Graphics Gems IV), r kept off 0 and 1
    float rr = clamp(r, 0.001, 0.999);
    float a = (1.0 / rr - 2.0) * (1.0 - 2.0 * x);
    return x < 0.5 ? x / (a + 1.0) : (a - x) / (a - 1.0);
}

vec3 node_hex_weights(vec3 luma, vec3 tile, float falloff) {
    // luminance x barycentric^7, normalised; then each through the gain, normalised again
    vec3 w = luma * pow(max(tile, vec3(0.0)), vec3(7.0));
    w /= w.x + w.y + w.z;
    if (falloff != 0.5) {
        w = vec3(node_hex_gain(w.x, falloff), node_hex_gain(w.y, falloff),
                 node_hex_gain(w.z, falloff));
        w /= w.x + w.y + w.z;
    }
    return w;
}

vec2 node_hex_tile(vec2 coord, vec2 vid, float rotation, vec2 rotation_range, float scale,
                   vec2 scale_range, float offset, vec2 offset_range) {
    // the lookup coordinate of the tile centred on grid vertex vid
    vec2 g = vid / (sqrt(3.0) * 2.0);
    vec2 centre = vec2(g.x + 0.5 * g.y, g.y / 1.15470054);
    vec2 rand = node_hex_hash(vid + vec2(0.12345));
    vec2 rr = radians(rotation_range);
    float angle = mix(rr.x, rr.y, rand.x * rotation);
    float k = mix(1.0, mix(scale_range.x, scale_range.y, rand.y), scale);
    vec2 off = mix(vec2(offset_range.x), vec2(offset_range.y), rand * offset);
    vec2 d = coord - centre;
    float c = cos(angle);
    float s = sin(angle);
    return vec2(c * d.x - s * d.y, s * d.x + c * d.y) / k + centre + off;
}

void node_hex_tiled_texture(sampler2D tex, vec2 uv, vec2 tiling, float rotation,
                            vec2 rotation_range, float scale, vec2 scale_range, float offset,
                            vec2 offset_range, float falloff, float falloff_contrast,
                            vec3 luma, out vec4 rgba, out vec3 rgb) {
    // the point's triangle of the skewed grid, its barycentric weights and its 3 vertices
    vec2 coord = uv * tiling;
    vec2 st = coord * (sqrt(3.0) * 2.0);
    vec2 sk = vec2(st.x - 0.57735027 * st.y, 1.15470054 * st.y);
    vec2 f = fract(sk);
    float z = 1.0 - f.x - f.y;
    float upper = step(0.0, -z);
    float s2 = 2.0 * upper - 1.0;
    vec3 tile = vec3(-z * s2, upper - f.y * s2, upper - f.x * s2);
    vec2 base = floor(sk);
    vec2 v1 = base + vec2(upper, upper);
    vec2 v2 = base + vec2(upper, 1.0 - upper);
    vec2 v3 = base + vec2(1.0 - upper, upper);
    vec4 c1 = texture(tex, node_hex_tile(coord, v1, rotation, rotation_range, scale,
                                         scale_range, offset, offset_range));
    vec4 c2 = texture(tex, node_hex_tile(coord, v2, rotation, rotation_range, scale,
                                         scale_range, offset, offset_range));
    vec4 c3 = texture(tex, node_hex_tile(coord, v3, rotation, rotation_range, scale,
                                         scale_range, offset, offset_range));
    vec3 lw = mix(vec3(1.0), vec3(dot(c1.rgb, luma), dot(c2.rgb, luma), dot(c3.rgb, luma)),
                  vec3(falloff_contrast));
    vec3 w = node_hex_weights(lw, tile, falloff);
    vec3 aw = node_hex_weights(vec3(1.0), tile, falloff);
    rgba = vec4(w.x * c1.rgb + w.y * c2.rgb + w.z * c3.rgb,
                aw.x * c1.a + aw.y * c2.a + aw.z * c3.a);
    rgb = rgba.rgb;
}
