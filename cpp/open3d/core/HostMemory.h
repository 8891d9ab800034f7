// How much host memory this process may still take, and a check before large allocations
// that refuses with the numbers instead of letting the kernel kill the process
// (docs/memory.md). Readers check the decoded scene, renderers their per-frame buffers,
// gs-bench its grid.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace open3d {
namespace core {

/// Bytes available now: MemAvailable of /proc/meminfo, lowered to what the cgroup's
/// memory.max leaves where one is set, and to OPEN3D_HOST_MEMORY_LIMIT (bytes, a cap for
/// tests and for leaving room to other programs) when that is set. UINT64_MAX when
/// nothing is known (no /proc).
uint64_t AvailableHostMemory();

/// A size in bytes as every flag and variable of the project spells it: a number with an
/// optional suffix K, M, G, T (powers of 1024; k = K), e.g. 2G, 512M, 1.5G, 123456. Throws
/// core::Open3DError naming `what` (a flag or variable) unless it is at least 1 byte and
/// finite.
uint64_t ParseByteCount(const std::string& text, const std::string& what);

/// The number of bytes an environment variable holds (OPEN3D_HOST_MEMORY_LIMIT,
/// OPEN3D_DEVICE_MEMORY_LIMIT) through ParseByteCount, nothing when it is unset or empty;
/// throws core::Open3DError naming the variable when it is not a size.
std::optional<uint64_t> ReadByteCountVariable(const char* name);

/// "1.23 GB" (powers of 1000, as free(1) -h and file managers show sizes).
std::string FormatBytes(uint64_t bytes);

/// Throws core::Open3DError "{what} needs {bytes} of memory, {available} is available
/// ({source}); {hint}" when `bytes` is more than AvailableHostMemory(). `hint` says what
/// would fit (fewer splats, a lower resolution); empty: none.
void RequireHostMemory(uint64_t bytes, const std::string& what, const std::string& hint = "");

}  // namespace core
}  // namespace open3d
