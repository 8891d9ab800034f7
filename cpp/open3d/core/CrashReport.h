// A crash (SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT) prints the signal and the call stack as
// module+offset frames to stderr before the process ends as it would have: a crash inside a
// driver on a machine without a debugger (the GPU device machine) can then be placed with
// `addr2line -f -e <the same build of the module> <offset>` afterwards.
#pragma once

namespace open3d {
namespace core {

/// Installs the handlers once per process (later calls do nothing). Each prints, then restores
/// the default action and re-raises, so exit codes and core dumps stay what they were.
void InstallCrashReport();

}  // namespace core
}  // namespace open3d
