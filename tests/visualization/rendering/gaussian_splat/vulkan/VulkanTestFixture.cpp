#include "VulkanTestFixture.h"

#include <cstdlib>
#include <iostream>
#include <string_view>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"

namespace open3d {
namespace tests {

using visualization::rendering::vulkan::CommandPool;
using visualization::rendering::vulkan::VulkanContext;
using visualization::rendering::vulkan::VulkanContextOptions;

std::unique_ptr<VulkanContext> VulkanTest::context_;
std::unique_ptr<CommandPool> VulkanTest::pool_;
std::string VulkanTest::skip_reason_;
std::string VulkanTest::failure_;

namespace {

bool EnvIs(const char* name, std::string_view value) {
    const char* env = std::getenv(name);
    return env != nullptr && value == env;
}

}  // namespace

std::unique_ptr<VulkanContext> VulkanTest::CreateTestContext(std::string& skip_reason,
                                                             std::string& failure) {
    VulkanContextOptions options;
    options.enable_validation = true;
    // Synchronization validation (missing or wrong barriers) is part of the check.
    options.enable_synchronization_validation = true;
    try {
        return VulkanContext::CreateHeadless(options);
    } catch (const core::Open3DError& with_validation) {
        // Tell "no device" (skip) from "device but no validation layer" (fail).
        try {
            options.enable_validation = false;
            VulkanContext::CreateHeadless(options);
            failure = with_validation.what();
        } catch (const core::Open3DError& without_validation) {
            if (EnvIs("OPEN3D_TEST_REQUIRE_VULKAN", "1")) {
                failure = without_validation.what();
            } else {
                skip_reason = std::string("no usable Vulkan device: ") + without_validation.what();
            }
        }
    }
    return nullptr;
}

void VulkanTest::SetUpTestSuite() {
    skip_reason_.clear();
    failure_.clear();
    context_ = CreateTestContext(skip_reason_, failure_);
    if (context_) pool_ = std::make_unique<CommandPool>(*context_);
}

void VulkanTest::SetUpTestSuiteOnOneLavapipeThread() {
    const char* old = std::getenv("LP_NUM_THREADS");
    const std::string saved = old ? old : "";
    setenv("LP_NUM_THREADS", "1", 1);
    SetUpTestSuite();
    if (old) {
        setenv("LP_NUM_THREADS", saved.c_str(), 1);
    } else {
        unsetenv("LP_NUM_THREADS");
    }
}

void VulkanTest::TearDownTestSuite() {
    // Messages sent while the device and instance are destroyed (e.g. leaked objects)
    // arrive after the context's counters are gone: count them through the log sink.
    int problems = 0;
    core::LogSink previous = core::SetLogSink(nullptr);
    core::SetLogSink([&](core::LogLevel level, std::string_view message) {
        if (level >= core::LogLevel::Warning) ++problems;
        if (previous) {
            previous(level, message);
        } else {
            std::cerr << message << "\n";
        }
    });
    pool_.reset();
    context_.reset();
    core::SetLogSink(previous);
    EXPECT_EQ(problems, 0) << "warnings or errors while destroying the Vulkan context";
}

void VulkanTest::SetUp() {
    if (!failure_.empty()) FAIL() << failure_;
    if (!context_) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(skip_reason_);
    if (!Context().IsValidationEnabled()) {
        std::cerr << "note: Vulkan validation is off (OPEN3D_VULKAN_VALIDATION=0)\n";
    }
    problems_before_ = Context().GetValidationMessageCounts().Problems();
}

void VulkanTest::TearDown() {
    if (!context_) return;
    Context().WaitIdle();
    EXPECT_EQ(Context().GetValidationMessageCounts().Problems(), problems_before_)
        << "the validation layer reported warnings or errors (see the log above)";
}

}  // namespace tests
}  // namespace open3d
