#include "open3d/visualization/rendering/gaussian_splat/BatchHostMemory.h"

#include <cstdlib>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"

namespace open3d {
namespace visualization {
namespace rendering {

BatchHostMemory::BatchHostMemory(size_t bytes) {
    if (bytes == 0) core::ThrowError("BatchHostMemory: the size must be > 0 bytes");
    const size_t rounded = (bytes + kAlignment - 1) / kAlignment * kAlignment;
    core::RequireHostMemory(rounded, "batch colours");
    auto block = std::make_shared<Block>();
    block->data = static_cast<uint8_t*>(std::aligned_alloc(kAlignment, rounded));
    if (block->data == nullptr) {
        core::ThrowError("BatchHostMemory: allocating {} failed", core::FormatBytes(rounded));
    }
    block->size = rounded;
    block_ = std::move(block);
}

BatchHostMemory::Block::~Block() { std::free(data); }

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
