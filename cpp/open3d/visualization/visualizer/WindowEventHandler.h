// What a window reports, in GLFW's terms (key and button codes, modifier bits, pixels with
// the origin at the top left). The Visualizer implements it; tests call it directly to
// inject input exactly as GLFW would deliver it.
#pragma once

#include <string>
#include <vector>

namespace open3d {
namespace visualization {

class WindowEventHandler {
public:
    virtual ~WindowEventHandler() = default;
    virtual void OnMouseButton(int button, bool pressed, int mods) = 0;
    virtual void OnCursorPos(double x, double y) = 0;
    virtual void OnScroll(double dx, double dy) = 0;
    virtual void OnKey(int key, bool pressed, bool repeat, int mods) = 0;
    virtual void OnChar(unsigned int codepoint) = 0;
    /// The drawable size changed; 0 x 0 while minimised.
    virtual void OnFramebufferSize(int width, int height) = 0;
    /// Files dropped on the window (drag and drop from a file manager).
    virtual void OnDrop(const std::vector<std::string>& paths) = 0;
};

}  // namespace visualization
}  // namespace open3d
