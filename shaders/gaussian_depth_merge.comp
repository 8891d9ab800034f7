#version 460
// Depth merge for depth readback (RenderToDepthImage): per pixel the nearer of the splat
// depth (a composite output, view-space z) and the scene depth (Filament's reversed-Z
// texture, converted to view-space z = near / d). Writes the merged view z (R32F, 0 where
// nothing is there) and a normalised R16UI value:
//   u = round(65535 * clamp((z - near) / (far - near), 0, 1)), and 65535 where nothing is.
// The splat depth counts where the composite's accumulated alpha is > 0 and >= range.w, so a
// faint haze need not hide what is behind it.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "GaussianSplatCompositeContract.h"

layout(local_size_x = kDepthMergeWorkgroupSize, local_size_y = kDepthMergeWorkgroupSize) in;

// 0: no scene depth; the texture binding is never read (the recorder binds a placeholder).
layout(constant_id = kSpecSceneDepth) const uint kSceneDepth = 0u;

layout(push_constant, std430) uniform PushConstantsBlock {
    GaussianDepthMergePushConstants pc;
};

layout(set = 0, binding = kDepthMergeSplatDepthBinding, r32f) readonly uniform image2D
    splat_depth;
layout(set = 0, binding = kDepthMergeSplatAlphaBinding, r32f) readonly uniform image2D
    splat_alpha;
layout(set = 0, binding = kDepthMergeSceneDepthBinding) uniform texture2D scene_depth;
layout(set = 0, binding = kDepthMergeNormalizedBinding, r16ui) writeonly uniform uimage2D
    out_normalized;
layout(set = 0, binding = kDepthMergeLinearBinding, r32f) writeonly uniform image2D out_linear;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(pc.width) || pixel.y >= int(pc.height)) return;
    const float kInfinity = uintBitsToFloat(0x7F800000u);

    float z = kInfinity;
    float alpha = imageLoad(splat_alpha, pixel).r;
    if (alpha > 0.0 && alpha >= pc.min_alpha) z = imageLoad(splat_depth, pixel).r;
    if (kSceneDepth != 0u) {
        // Reversed-Z, infinite far plane, cleared to 0: z_view = near / d (as in the composite).
        int y = pc.scene_depth_flip_y != 0u ? int(pc.height) - 1 - pixel.y : pixel.y;
        float d = texelFetch(scene_depth, ivec2(pixel.x, y), 0).r;
        if (d > 0.0) z = min(z, pc.scene_near / d);
    }
    bool found = z < kInfinity;
    float normalized = clamp((z - pc.near_plane) / (pc.far_plane - pc.near_plane), 0.0, 1.0);
    imageStore(out_linear, pixel, vec4(found ? z : 0.0));
    imageStore(out_normalized, pixel, uvec4(found ? uint(round(normalized * 65535.0)) : 65535u));
}
