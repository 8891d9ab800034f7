// Sends a key press and release to an X11 window through the X server (XSendEvent), as
// another client would: the viewer sees it only when it polls its events. Kept apart from
// the tests because Xlib's macros (None, True, KeyPress...) clash with other headers.
#pragma once

#include <cstdint>
#include <string>

namespace open3d {
namespace tests {

/// `keysym` is an X keysym name ("q", "Escape"). Returns false when no display opens.
bool SendXKey(uint64_t window, const std::string& keysym);

}  // namespace tests
}  // namespace open3d
