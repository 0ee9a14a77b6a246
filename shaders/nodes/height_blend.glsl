// Layer Blend (height) node: the layer shows where its height rises above the base's,
// through a soft transition of width 2 contrast centred where the heights are equal.
#include "layer_blend.glsl"

// The height blend's weight: t = smoothstep(-c, c, layer_height - base_height), c kept above
// 0, where GLSL's smoothstep is undefined (edge0 >= edge1). The preview's hidden-layer guard
// (layer_guard.glsl) reads it too.
float heightBlendWeight(float base_height, float layer_height, float contrast) {
    // Height blend weight: a smoothstep of the height difference, width 2 c
    float c = max(contrast, 1e-5);
    return smoothstep(-c, c, layer_height - base_height);
}

void node_height_blend(MaterialAttributes base, MaterialAttributes layer, float base_height,
                       float layer_height, float contrast, out MaterialAttributes result) {
    // Height blend: the mask blend by the weight of the two heights
    result = blendMaterialAttributes(base, layer,
                                     heightBlendWeight(base_height, layer_height, contrast));
}
