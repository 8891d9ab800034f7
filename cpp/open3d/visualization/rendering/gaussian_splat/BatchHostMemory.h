// Host memory for batch colours that a GPU backend may let the device write directly: the
// Vulkan backend imports it (VK_EXT_external_memory_host), so a batch read back to the host
// needs no copy on the host (docs/vulkan.md "Submission path"). Any backend accepts it as
// ordinary memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

namespace open3d {
namespace visualization {
namespace rendering {

class BatchHostMemory {
public:
    /// Alignment and size granule of the allocation: a multiple of every device's
    /// minImportedHostPointerAlignment seen (4 KiB on NVIDIA and lavapipe).
    static constexpr size_t kAlignment = size_t(64) << 10;

    /// No memory (Data() is nullptr).
    BatchHostMemory() = default;
    /// `bytes` (> 0) of uninitialised memory, rounded up to kAlignment. Copies share it; it
    /// is freed when the last copy, and every backend that imported it, let go. Throws
    /// core::Open3DError when the allocation fails or the host lacks the memory.
    explicit BatchHostMemory(size_t bytes);

    uint8_t* Data() const { return block_ ? block_->data : nullptr; }
    /// Bytes usable from Data() (the rounded-up size).
    size_t Size() const { return block_ ? block_->size : 0; }
    explicit operator bool() const { return block_ != nullptr; }
    /// Holders of the memory (this and its copies, importing backends included).
    long UseCount() const { return block_.use_count(); }
    bool SameMemory(const BatchHostMemory& other) const { return block_ == other.block_; }

private:
    struct Block {
        uint8_t* data = nullptr;
        size_t size = 0;
        ~Block();
    };
    std::shared_ptr<Block> block_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
