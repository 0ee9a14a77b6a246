// Shared band-limiting helpers (not a node kind): pattern edges box-filtered over a
// footprint w, the pixel's extent in the pattern's own units (fwidth of its coordinate,
// times the node's filter_width). w = 0 gives the hard, unfiltered edge exactly.

float nodeFilteredStep(float edge, float x, float w) {
    // Box filter of step(edge, x) over [x - w/2, x + w/2]: a linear ramp of width w
    return w > 0.0 ? clamp((x - edge) / w + 0.5, 0.0, 1.0) : step(edge, x);
}

float nodePulseIntegral(float x, float duty) {
    // Integral from 0 to x of the period-1 pulse train that is 1 on [0, duty)
    float i = floor(x);
    return i * duty + min(x - i, duty);
}

float nodeFilteredPulse(float x, float duty, float w) {
    // Apodaca & Gritz 2000, "Advanced RenderMan", ch. 11: box-filtered pulse train from
    // the difference of its integral; x is reduced to one period first, so the result is
    // as precise far from the origin as near it
    x = x - floor(x);
    if (w <= 0.0) {
        return x < duty ? 1.0 : 0.0;
    }
    return (nodePulseIntegral(x + 0.5 * w, duty) - nodePulseIntegral(x - 0.5 * w, duty)) / w;
}

float nodeSquareIntegral(float x) {
    // Integral from 0 to x of the period-2 square wave, +1 on [0, 1) and -1 on [1, 2)
    return 1.0 - abs(x - 2.0 * floor(0.5 * x) - 1.0);
}

float nodeFilteredSquare(float x, float w) {
    // Quilez, "Filtering the checkerboard pattern": box-filtered square wave (+1 where
    // floor(x) is even), reduced to one period first
    x = x - 2.0 * floor(0.5 * x);
    if (w <= 0.0) {
        return x < 1.0 ? 1.0 : -1.0;
    }
    return (nodeSquareIntegral(x + 0.5 * w) - nodeSquareIntegral(x - 0.5 * w)) / w;
}
