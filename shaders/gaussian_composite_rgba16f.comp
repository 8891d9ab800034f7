#version 460
// Composite stage composite with an RGBA16F colour image: the premultiplied overlay Filament draws
// over its own colour (docs/filament.md "Frame"). Body and design: gaussian_composite.glsl.
#define OPEN3D_COMPOSITE_COLOR_FORMAT rgba16f
#extension GL_GOOGLE_include_directive : require
#include "gaussian_composite.glsl"
