// Bricks node: running-bond bricks or tiles with filtered mortar.
#include "noise_lib.glsl"
#include "filter_lib.glsl"

void node_bricks(vec2 uv, vec2 count, float mortar, float bevel, float offset, float seed,
                 float filter_width, out float mask, out float height, out float tile_id,
                 out vec2 tile_uv) {
    // Running bond (Ebert et al. 2003, ch. 2 "brick"): rows shifted by offset bricks, the
    // distance to the brick border in UV units thresholded at half the mortar width and
    // box-filtered over its footprint; a rounded bevel ramp for the height
    vec2 p = uv * count;
    float row = floor(p.y);
    p.x += offset * row;
    vec2 cell = floor(p);
    vec2 f = p - cell;
    vec2 size = 1.0 / max(abs(count), vec2(1e-6));
    vec2 border = min(f, 1.0 - f) * size;
    float e = min(border.x, border.y);
    float half_mortar = 0.5 * mortar;
    mask = nodeFilteredStep(half_mortar, e, fwidth(e) * filter_width);
    float t = clamp((e - half_mortar) / max(bevel, 1e-6), 0.0, 1.0);
    height = t * (2.0 - t);
    tile_id = nodeHashUnit(nodeHashCell2(ivec2(cell), nodeSeed(seed)));
    tile_uv = f;
}
