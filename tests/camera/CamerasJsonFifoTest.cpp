// cameras.json given as a FIFO (named pipe): refused with the reason, where opening it used
// to block forever waiting for a writer (with the bug this test hangs until ctest's timeout).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"

namespace open3d {
namespace tests {
namespace {

TEST(CamerasJson, FifoIsRefusedInsteadOfBlocking) {
    const std::string fifo = TempDir() + "/cameras.json";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
    try {
        camera::ReadCamerasJson(fifo);
        ADD_FAILURE() << "no error reading a FIFO";
    } catch (const core::Open3DError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(fifo), std::string::npos) << message;
        EXPECT_NE(message.find("not a regular file"), std::string::npos) << message;
    }
}

}  // namespace
}  // namespace tests
}  // namespace open3d
