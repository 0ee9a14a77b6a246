// Common maths shared by every shading file: constants and small helpers.
// Included once per shader by matedit's assembler; defines no uniforms.

const float PI = 3.14159265358979;
const float INV_PI = 0.318309886183791;

float saturate(float x) { return clamp(x, 0.0, 1.0); }
vec2 saturate(vec2 x) { return clamp(x, 0.0, 1.0); }
vec3 saturate(vec3 x) { return clamp(x, 0.0, 1.0); }

float sq(float x) { return x * x; }

float pow5(float x) {
    float x2 = x * x;
    return x2 * x2 * x;
}
