// Layer Blend (height) node: the layer shows where its height rises above the base's,
// through a soft transition of width 2 contrast centred where the heights are equal.
#include "layer_blend.glsl"

void node_height_blend(MaterialAttributes base, MaterialAttributes layer, float base_height,
                       float layer_height, float contrast, out MaterialAttributes result) {
    // Height blend: weight t = smoothstep(-c, c, layer_height - base_height), then the
    // mask blend; c is kept above 0, where GLSL's smoothstep is undefined (edge0 >= edge1)
    float c = max(contrast, 1e-5);
    float t = smoothstep(-c, c, layer_height - base_height);
    result = blendMaterialAttributes(base, layer, t);
}
