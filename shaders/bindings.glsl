// Layout qualifiers for uniform blocks and samplers, per dialect.
// The compiler defines MATEDIT_UBO and MATEDIT_BINDING for each target; these fallbacks let a
// library file compile on its own: std140 everywhere, plus a binding where the dialect allows
// one (Vulkan GLSL requires it; GLSL 330 and ESSL 300 have none).

#ifndef MATEDIT_UBO
#ifdef VULKAN
#define MATEDIT_UBO(n) layout(std140, binding = n)
#else
#define MATEDIT_UBO(n) layout(std140)
#endif
#endif

#ifndef MATEDIT_BINDING
#ifdef VULKAN
#define MATEDIT_BINDING(n) layout(binding = n)
#else
#define MATEDIT_BINDING(n)
#endif
#endif
