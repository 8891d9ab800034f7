#version 460
// Composite stage composite with an RGBA32F colour image: headless readback, where RGBA16F's
// quantisation alone (~77 dB PSNR) would miss the 80 dB accuracy target. Body and design:
// gaussian_composite.glsl.
#define OPEN3D_COMPOSITE_COLOR_FORMAT rgba32f
#extension GL_GOOGLE_include_directive : require
#include "gaussian_composite.glsl"
