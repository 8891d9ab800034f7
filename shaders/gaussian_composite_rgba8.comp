#version 460
// Composite stage composite with an RGBA8 (UNORM) colour image: batched rendering of 8-bit
// images, a quarter of the bytes of RGBA32F to copy to the host. The store converts with the
// device's float-to-unorm rounding. Body and design: gaussian_composite.glsl.
#define OPEN3D_COMPOSITE_COLOR_FORMAT rgba8
#extension GL_GOOGLE_include_directive : require
#include "gaussian_composite.glsl"
