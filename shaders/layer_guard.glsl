// The preview's hidden-layer guard (matedit.compiler.schedule.hidden_layer_guards): a layer of
// a stack is evaluated only where its weight is non-zero somewhere in the pixel's 2x2 quad.
// Where the weight is 0 the blend gives the stack below exactly, whatever the layer holds, so
// skipping it changes no pixel; testing the whole quad keeps the branch uniform across it, so
// derivatives inside the layer (bump from height, filtered steps) stay defined.
//
// Fine derivatives reach the quad's other pixels: |w| plus the horizontal difference is
// non-zero where the pixel or its row neighbour has a weight; the vertical difference of that
// spreads it down the column. GLSL 4.50 has dFdxFine in core; at 3.30 the includer's prelude
// enables GL_ARB_derivative_control, which Mesa offers at any version (the extension itself
// asks for GLSL 4.00, so glslang refuses it at 3.30, and a driver that does the same makes
// the preview link the variant without guards: matedit.render.programs). Elsewhere (ESSL
// 3.00, coarse derivatives only, or no extension) every layer is evaluated.

bool layerShows(float w) {
    // Whether the weight is non-zero anywhere in the quad (derivatives: GLSL 4.50, 8.14.1)
#if __VERSION__ >= 450 || (defined(MATEDIT_DERIVATIVE_CONTROL) && defined(GL_ARB_derivative_control))
    float row = abs(w) + abs(dFdxFine(w));
    // NaN compares unequal: a layer whose weight is not a number is evaluated
    return !(row + abs(dFdyFine(row)) == 0.0);
#else
    return true;
#endif
}
