"""The node library (the 89 kinds added after the first catalogue: noise, patterns, colour,
maths, UV and space, normals, masks), by name: the kinds the library tests walk. Named
here: the package keeps one catalogue, in category modules, with no record of which kinds
came later."""

LIBRARY_KINDS = (
    "atan2", "exp", "log", "mod", "sign", "round", "ceil", "trunc", "negate", "reciprocal",
    "tan", "asin", "acos", "radians", "degrees", "multiply_add", "posterize", "smooth_min",
    "distance", "reflect", "refract", "if_greater", "if_equal", "fwidth",
    "luminance", "rgb_to_hsv", "hsv_to_rgb", "hsv_adjust", "brightness_contrast", "gamma",
    "invert", "levels", "saturation", "srgb_to_linear", "linear_to_srgb",
    "blend_multiply", "blend_screen", "blend_overlay", "blend_soft_light", "blend_add",
    "blend_subtract", "blend_difference", "blend_dodge", "blend_burn", "blend_lighten",
    "blend_darken", "color_ramp",
    "gradient_noise", "gradient_noise_3d", "cellular_noise", "cellular_noise_3d", "fbm",
    "fbm_3d", "ridged_noise", "white_noise", "cell_hash", "domain_warp",
    "bricks", "stripes", "wave", "rings", "radial_gradient", "spherical_gradient",
    "filtered_step", "filtered_smoothstep",
    "tiling_offset", "rotate_uv", "panner", "polar_coordinates", "object_position", "tangent",
    "bitangent", "tangent_to_world", "world_to_tangent", "object_to_world", "world_to_object",
    "world_to_view", "view_to_world", "triplanar_mapping", "triplanar_blend",
    "triplanar_texture",
    "normal_from_height", "normal_strength", "flip_green",
    "fresnel", "facing_ratio", "slope_mask", "height_mask", "curvature",
)
