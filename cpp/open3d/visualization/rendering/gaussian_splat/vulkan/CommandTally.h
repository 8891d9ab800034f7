// Counts the dispatches and barriers a recording holds, so a frame can say how many dependent
// steps it is made of (docs/vulkan.md "Counting a frame's dispatches"). Every recorder
// dispatches through RecordDispatch / RecordDispatchIndirect and every barrier goes through
// RecordMemoryBarrier or RecordImageBarrier, which report here.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

/// What one recording holds.
struct CommandCounts {
    int dispatches = 0;  ///< vkCmdDispatch and vkCmdDispatchIndirect
    int barriers = 0;    ///< pipeline barriers (memory and image)
    /// Dispatches with a barrier between them and the dispatch before (the first counts too):
    /// the length of the chain of dispatches that wait for each other.
    int dependent_dispatches = 0;
};

/// Counts what this thread records while it lives. Tallies nest: an inner one counts alone,
/// and the outer one resumes after it.
class CommandTally {
public:
    CommandTally();
    ~CommandTally();
    CommandTally(const CommandTally&) = delete;
    CommandTally& operator=(const CommandTally&) = delete;
    const CommandCounts& Counts() const { return counts_; }

    /// Called by the record helpers; no-ops without a tally on this thread.
    static void NoteDispatch();
    static void NoteBarrier();

private:
    CommandCounts counts_;
    bool barrier_since_dispatch_ = true;
    CommandTally* outer_ = nullptr;
};

/// vkCmdDispatch, counted.
void RecordDispatch(VkCommandBuffer cmd, uint32_t x, uint32_t y, uint32_t z);
/// vkCmdDispatchIndirect, counted.
void RecordDispatchIndirect(VkCommandBuffer cmd, VkBuffer buffer, VkDeviceSize offset);

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
