// How far a long operation on the calling thread is (reading a large file, decoding it,
// encoding a compressed one), reported through a thread-local callback so that code deep in
// a reader needs no extra parameter. gs-convert installs one that draws a progress bar;
// without a callback ReportProgress does nothing. Reports come from the thread that runs the
// operation (never from ParallelFor's workers), with fractions in [0, 1] that do not go back
// within one stage.
//
//   core::ScopedProgressCallback bar([](const char* stage, double f) { Draw(stage, f); });
#pragma once

#include <functional>

namespace open3d {
namespace core {

using ProgressCallback = std::function<void(const char* stage, double fraction)>;

/// True when the calling thread has a callback installed (work may then split itself into
/// reportable steps).
bool HasProgressCallback();
/// Calls the calling thread's callback with `stage` ("reading", "decoding", "clustering",
/// "compressing", "level of detail") and `fraction` clamped to [0, 1]; nothing without one.
void ReportProgress(const char* stage, double fraction);

/// Installs `callback` for the calling thread until destroyed (then restores the previous).
class ScopedProgressCallback {
public:
    explicit ScopedProgressCallback(ProgressCallback callback);
    ~ScopedProgressCallback();
    ScopedProgressCallback(const ScopedProgressCallback&) = delete;
    ScopedProgressCallback& operator=(const ScopedProgressCallback&) = delete;

private:
    ProgressCallback previous_;
};

}  // namespace core
}  // namespace open3d
