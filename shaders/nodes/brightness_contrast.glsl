// Brightness / Contrast node.

void node_brightness_contrast(vec3 color, float brightness, float contrast, out vec3 result) {
    // Blender's Bright/Contrast: (1 + c) x + (b - c / 2), clamped at 0 (pivot at 0.5)
    float a = 1.0 + contrast;
    float b = brightness - contrast * 0.5;
    result = max(a * color + b, 0.0);
}
