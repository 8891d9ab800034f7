#include "open3d/visualization/rendering/gaussian_splat/vulkan/CommandTally.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {
namespace {

thread_local CommandTally* active_tally = nullptr;

}  // namespace

CommandTally::CommandTally() : outer_(active_tally) { active_tally = this; }

CommandTally::~CommandTally() { active_tally = outer_; }

void CommandTally::NoteDispatch() {
    CommandTally* tally = active_tally;
    if (tally == nullptr) return;
    ++tally->counts_.dispatches;
    if (tally->barrier_since_dispatch_) ++tally->counts_.dependent_dispatches;
    tally->barrier_since_dispatch_ = false;
}

void CommandTally::NoteBarrier() {
    CommandTally* tally = active_tally;
    if (tally == nullptr) return;
    ++tally->counts_.barriers;
    tally->barrier_since_dispatch_ = true;
}

void RecordDispatch(VkCommandBuffer cmd, uint32_t x, uint32_t y, uint32_t z) {
    CommandTally::NoteDispatch();
    vkCmdDispatch(cmd, x, y, z);
}

void RecordDispatchIndirect(VkCommandBuffer cmd, VkBuffer buffer, VkDeviceSize offset) {
    CommandTally::NoteDispatch();
    vkCmdDispatchIndirect(cmd, buffer, offset);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
