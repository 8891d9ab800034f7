// Fixture of the Vulkan tests: one headless context per test suite with validation on
// (creating one per test would cost more than most tests), a skip with the reason when no
// Vulkan device exists (a failure in CI: OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE), and a failure when
// the validation layer sent any warning or error during a test or while the suite's context was
// destroyed.
//
// Environment: CI=true or OPEN3D_TEST_REQUIRE_VULKAN=1 turns "no device" into a failure
// (machines that must run these tests); OPEN3D_VULKAN_VALIDATION=0 runs them without the
// validation layer (machines without it, e.g. a GPU box with only the loader).
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace tests {

/// The backend's stage path: the geometry stage submitted on its own, then the composite (what
/// the Filament integration runs, with its skips). Render and RenderBatch take the
/// submission path instead.
inline visualization::rendering::RenderOutput RenderStages(
    visualization::rendering::vulkan::GaussianSplatVulkanBackend& backend,
    const camera::PinholeCamera& camera, const visualization::rendering::RenderConfig& config,
    const visualization::rendering::CompositeInputs& inputs = {}) {
    backend.RenderGeometryStage(camera, config);
    visualization::rendering::RenderOutput out;
    backend.RenderCompositeStage(out, inputs);
    return out;
}

class VulkanTest : public ::testing::Test {
protected:
    static void SetUpTestSuite();
    /// SetUpTestSuite with LP_NUM_THREADS=1 while the instance is made: lavapipe then runs
    /// workgroups one after another, so no decoupled look-back (the one-sweep sort, the
    /// chained emit) ever waits for a workgroup the OS descheduled, which with lavapipe's
    /// loop limit would make results depend on the machine's load (docs/radix-sort.md
    /// "One sweep on CPU devices"). A GPU ignores the variable.
    static void SetUpTestSuiteOnOneLavapipeThread();
    static void TearDownTestSuite();
    void SetUp() override;
    void TearDown() override;

    static visualization::rendering::vulkan::VulkanContext& Context() { return *context_; }
    /// The shared context's handles, for backends that borrow them.
    static visualization::rendering::vulkan::BorrowedVulkanHandles BorrowedHandles() {
        visualization::rendering::vulkan::BorrowedVulkanHandles handles;
        handles.instance = Context().GetInstance();
        handles.physical_device = Context().GetPhysicalDevice();
        handles.device = Context().GetDevice();
        handles.queue = Context().GetQueue();
        handles.queue_family_index = Context().GetQueueFamilyIndex();
        // Readback copies then take the copy engines where the device has them (NVIDIA).
        handles.transfer_queue = Context().GetTransferQueue();
        handles.transfer_queue_family_index = Context().GetTransferQueueFamilyIndex();
        handles.host_memory_import_enabled = Context().CanImportHostMemory();
        handles.external_semaphore_fd_enabled = Context().SupportsExternalSemaphoreFd();
        return handles;
    }
    static visualization::rendering::vulkan::CommandPool& Pool() { return *pool_; }
    /// A Vulkan backend on the shared device, so the validation check covers it;
    /// `max_workgroups_x` as BorrowedVulkanHandles says (0: the device's).
    static std::unique_ptr<visualization::rendering::vulkan::GaussianSplatVulkanBackend>
    MakeBackend(uint32_t entry_capacity = 1u << 22, uint32_t max_workgroups_x = 0) {
        visualization::rendering::vulkan::BorrowedVulkanHandles handles = BorrowedHandles();
        handles.max_workgroups_x = max_workgroups_x;
        return std::make_unique<visualization::rendering::vulkan::GaussianSplatVulkanBackend>(
            visualization::rendering::vulkan::VulkanContext::CreateFromBorrowed(handles),
            entry_capacity);
    }

    /// Creates a context as the fixture does; on failure returns nullptr and sets
    /// `skip_reason` (no device) or `failure` (device present, validation layer missing).
    static std::unique_ptr<visualization::rendering::vulkan::VulkanContext> CreateTestContext(
        std::string& skip_reason, std::string& failure);

private:
    static std::unique_ptr<visualization::rendering::vulkan::VulkanContext> context_;
    static std::unique_ptr<visualization::rendering::vulkan::CommandPool> pool_;
    static std::string skip_reason_;
    static std::string failure_;
    uint64_t problems_before_ = 0;
};

}  // namespace tests
}  // namespace open3d
