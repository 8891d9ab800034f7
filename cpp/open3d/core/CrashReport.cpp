#include "open3d/core/CrashReport.h"

#include <execinfo.h>
#include <signal.h>
#include <unistd.h>

#include <cstring>
#include <mutex>

namespace open3d {
namespace core {

namespace {

constexpr int kSignals[] = {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT};

// Only async-signal-safe calls: write, backtrace_symbols_fd (backtrace itself is made safe by
// calling it once before any crash, which loads libgcc), signal, raise.
void Write(const char* text) {
    ssize_t ignored = write(STDERR_FILENO, text, std::strlen(text));
    (void)ignored;
}

void OnCrash(int signal_number) {
    Write("\n*** open3d: fatal signal ");
    Write(strsignal(signal_number));
    Write("; call stack (module(+offset) [address]), innermost first:\n");
    void* frames[64];
    const int count = backtrace(frames, 64);
    backtrace_symbols_fd(frames, count, STDERR_FILENO);
    signal(signal_number, SIG_DFL);
    raise(signal_number);
}

}  // namespace

void InstallCrashReport() {
    static std::once_flag once;
    std::call_once(once, [] {
        void* warm_up[1];
        backtrace(warm_up, 1);
        for (int s : kSignals) signal(s, OnCrash);
    });
}

}  // namespace core
}  // namespace open3d
