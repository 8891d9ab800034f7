// The base of the GPU contract between host code and compute shaders (STYLE.md point 5),
// included by every stage's contract header: the shared float-exact arithmetic
// (GaussianSplatShared.h), the GLSL vector types the C++ mirrors of buffer structs use, and
// the error flags every stage reports. One header per stage follows it (radix sort,
// projection, tile lists, composite), so a stage's layout changes where only its users look.
// Compiled as GLSL (#include from shaders/*.comp through GL_GOOGLE_include_directive) and as
// C++ (namespace open3d::visualization::rendering::shader), where every mirrored struct gets
// static_asserts on size and member offsets. Structs use 4-byte scalars, vec3 followed by a
// scalar, and 16-byte vectors only, so std430 (and std140) agree with C++ without hidden
// padding. Never includes Vulkan headers: the CPU and Metal layers may read it too.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_COMMON_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_COMMON_H

#include "GaussianSplatShared.h"

#ifdef __cplusplus
#include <cstddef>

namespace open3d {
namespace visualization {
namespace rendering {
namespace shader {

// GLSL's uvec4 as std430 lays it out.
struct alignas(16) uvec4 {
    uvec4() = default;  // constructors for clang 14, as vec4's (GaussianSplatShared.h)
    constexpr uvec4(uint32_t x_, uint32_t y_, uint32_t z_, uint32_t w_)
        : x(x_), y(y_), z(z_), w(w_) {}
    uint32_t x, y, z, w;
};
// GLSL's vec3: std430 aligns it to 16 bytes but it takes 12, so a 4-byte scalar may follow
// in the same 16 bytes. The C++ struct has 4-byte alignment: every vec3 member's offset is
// static_asserted to be a multiple of 16, and a named scalar fills the remaining 4 bytes.
// Never in arrays (GLSL pads vec3 array elements to 16 bytes).
struct vec3 {
    float x, y, z;
};
static_assert(sizeof(vec4) == 16 && sizeof(uvec4) == 16 && sizeof(vec3) == 12);
#endif

// ---- Error flags (same bits as RenderStats::error_flags, checked in RadixSort.cpp) ----
OPEN3D_SHADER_CONST uint kErrorEntriesDropped = 1u;
OPEN3D_SHADER_CONST uint kErrorCountsClamped = 2u;

// ---- Workgroup grids past maxComputeWorkGroupCount[0] ----
// Vulkan guarantees 65,535 workgroups along each axis of a dispatch, and lavapipe and many
// integrated and mobile GPUs give no more along x (NVIDIA gives 2^31 - 1). A pass over more
// workgroups than max_x lays them out in rows: (x, y, 1, 0) with x <= max_x, the fewest rows
// y and fewer than y spare workgroups (x * y - groups). Shaders number their workgroup
// row-major (FlatWorkGroupIndex) and the spare ones find nothing past the count, so on a
// device whose x axis holds the whole pass the grid is the one-row grid it was.
OPEN3D_SHADER_FUNC uvec4 DispatchGridFor(uint groups, uint max_x) {
    uint width = max_x < 1u ? 1u : max_x;
    if (groups <= width) return uvec4(groups, 1u, 1u, 0u);
    uint rows = (groups - 1u) / width + 1u;
    return uvec4((groups - 1u) / rows + 1u, rows, 1u, 0u);
}

#ifndef __cplusplus
// The row-major index of this workgroup in a grid from DispatchGridFor (compute shaders).
uint FlatWorkGroupIndex() { return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x; }
// Workgroups in this dispatch's grid.
uint FlatNumWorkGroups() { return gl_NumWorkGroups.x * gl_NumWorkGroups.y; }
#endif

#ifdef __cplusplus
static_assert(kErrorEntriesDropped == 1u && kErrorCountsClamped == 2u);
}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_COMMON_H
