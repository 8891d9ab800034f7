#include "visualization/visualizer/XKeySender.h"

#include <X11/Xlib.h>

namespace open3d {
namespace tests {

bool SendXKey(uint64_t window, const std::string& keysym) {
    Display* display = XOpenDisplay(nullptr);
    if (display == nullptr) return false;
    XKeyEvent event{};
    event.display = display;
    event.window = static_cast<Window>(window);
    event.root = DefaultRootWindow(display);
    event.subwindow = None;
    event.time = CurrentTime;
    event.same_screen = True;
    event.keycode = XKeysymToKeycode(display, XStringToKeysym(keysym.c_str()));
    event.type = KeyPress;
    XSendEvent(display, event.window, True, KeyPressMask, reinterpret_cast<XEvent*>(&event));
    event.type = KeyRelease;
    XSendEvent(display, event.window, True, KeyReleaseMask, reinterpret_cast<XEvent*>(&event));
    XFlush(display);
    XCloseDisplay(display);
    return true;
}

}  // namespace tests
}  // namespace open3d
