// Bricks node: running-bond bricks or tiles with filtered mortar.
#include "noise_lib.glsl"
#include "filter_lib.glsl"

void node_bricks(vec2 uv, vec2 count, float mortar, float bevel, float offset, float seed,
                 float filter_width, out float mask, out float height, out float tile_id,
                 out vec2 tile_uv) {
    // Running bond (Ebert et al. 2003, ch. 2 "brick"): rows shifted by offset bricks; the
    // mask is the product of two pulse trains (brick interiors across and up), each
    // box-filtered over its pixel footprint, so far away it tends to the brick's share of
    // the area; a rounded bevel ramp of the distance to the border for the height
    vec2 p = uv * count;
    float row = floor(p.y);
    p.x += offset * row;
    vec2 cell = floor(p);
    vec2 f = p - cell;
    vec2 size = 1.0 / max(abs(count), vec2(1e-6));
    vec2 border = min(f, 1.0 - f) * size;
    float e = min(border.x, border.y);
    float half_mortar = 0.5 * mortar;
    vec2 m = clamp(mortar * abs(count), 0.0, 1.0);  // mortar in brick units, per axis
    vec2 w = fwidth(p) * filter_width;
    mask = nodeFilteredPulse(p.x - 0.5 * m.x, 1.0 - m.x, w.x)
         * nodeFilteredPulse(p.y - 0.5 * m.y, 1.0 - m.y, w.y);
    float t = clamp((e - half_mortar) / max(bevel, 1e-6), 0.0, 1.0);
    height = t * (2.0 - t);
    tile_id = nodeHashUnit(nodeHashCell2(ivec2(cell), nodeSeed(seed)));
    tile_uv = f;
}
