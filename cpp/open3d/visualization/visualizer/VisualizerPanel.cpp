// The settings panel of the Visualizer (docs/viewer.md "Panel"): ImGui widgets only; the
// ImGuiOverlay turns them into a Filament view drawn over the scene.
#include <imgui.h>

#include <filesystem>
#include <utility>

#include <fmt/format.h>

#include "open3d/visualization/visualizer/Visualizer.h"

namespace open3d {
namespace visualization {

namespace {

const ImVec4 kWarning(1.0f, 0.45f, 0.3f, 1.0f);

void FrameSection(const Visualizer& vis) {
    const FrameStatistics& stats = vis.GetFrameStatistics();
    const double frame_ms = stats.GetSmoothedFrameMs();
    ImGui::Text("Frame %.1f ms (%.1f fps)", frame_ms, frame_ms > 0.0 ? 1000.0 / frame_ms : 0.0);
    if (vis.GetLastFrameDivisor() > 1) {
        ImGui::TextDisabled("Drawn at 1/%d size while moving", vis.GetLastFrameDivisor());
    }
    const rendering::FrameTimes& t = stats.GetSmoothedParts();
    ImGui::Text("Renderer %.1f ms: geometry %.1f", t.total_ms, t.geometry_stage_ms);
    ImGui::Text("  Filament %.1f, composite %.1f, compose %.1f", t.filament_ms,
                t.composite_stage_ms, t.compose_ms);
    const uint32_t flags = vis.GetLastFrame().splat_stats.error_flags;
    if (flags != 0) ImGui::TextColored(kWarning, "GPU error flags 0x%x (see Splats)", flags);
}

void GpuSection(const Visualizer& vis) {
    const rendering::RenderStats& s = vis.GetLastFrame().splat_stats;
    if (s.geometry_reused) ImGui::TextDisabled("Geometry stage reused (nothing moved)");
    ImGui::Text("project %.2f ms", s.gpu_project_ms);
    ImGui::Text("sort %.2f ms (depth %.2f,", s.gpu_sort_ms, s.gpu_depth_sort_ms);
    ImGui::Text("  scan+emit %.2f, tiles %.2f)", s.gpu_scan_emit_ms, s.gpu_tile_sort_ms);
    ImGui::Text("composite %.2f ms", s.gpu_composite_ms);
}

void SplatSection(const Visualizer& vis) {
    const rendering::RenderStats& s = vis.GetLastFrame().splat_stats;
    ImGui::Text("Splats %lld, visible %lld", static_cast<long long>(s.num_splats),
                static_cast<long long>(s.num_visible));
    ImGui::Text("Tile entries %lld", static_cast<long long>(s.num_tile_entries));
    ImGui::Text("GPU scene %.1f MiB", s.gpu_scene_bytes / (1024.0 * 1024.0));
    if (s.error_flags == 0) {
        ImGui::Text("GPU errors: none");
    } else {
        ImGui::TextColored(kWarning, "GPU errors: 0x%x%s%s", s.error_flags,
                           (s.error_flags & rendering::kEntriesDropped) ? " entries dropped" : "",
                           (s.error_flags & rendering::kCountsClamped) ? " counts clamped" : "");
    }
}

void RenderingSection(Visualizer& vis) {
    // A copy, written back only when a widget changed it: the non-const accessor asks for a
    // redraw, and calling it every frame kept the viewer drawing forever.
    rendering::RenderConfig config = std::as_const(vis).GetSplatConfig();
    bool changed = ImGui::SliderInt("SH degree cap", &config.sh_degree, 0, 3);
    changed |= ImGui::Checkbox("Antialias", &config.antialias);
    if (changed) vis.SetSplatConfig(config);
    const Eigen::Vector4f& bg = vis.GetBackground();
    float rgb[3] = {bg[0], bg[1], bg[2]};
    if (ImGui::ColorEdit3("Background", rgb)) {
        vis.SetBackground(Eigen::Vector4f(rgb[0], rgb[1], rgb[2], bg[3]));
    }
}

void ObjectSection(Visualizer& vis) {
    if (const auto progress = vis.GetStreamProgress()) {
        bool visible = vis.IsStreamVisible();
        const std::string label =
            fmt::format("    stream {}", std::filesystem::path(progress->path).filename().string());
        if (ImGui::Checkbox(label.c_str(), &visible)) vis.ShowStream(visible);
    }
    const std::vector<std::string>& names = vis.GetGeometryNames();
    for (size_t i = 0; i < names.size(); ++i) {
        bool visible = vis.IsGeometryVisible(names[i]);
        // fmt, not operator+: GCC 12 -O3 reports a false -Wrestrict on the string sums.
        const std::string label =
            i < 9 ? fmt::format("[{}] {}", i + 1, names[i]) : fmt::format("    {}", names[i]);
        if (ImGui::Checkbox(label.c_str(), &visible)) vis.ShowGeometry(names[i], visible);
    }
    if (names.empty() && !vis.GetStreamProgress()) ImGui::TextDisabled("(no geometry)");
}

}  // namespace

void Visualizer::BuildPanel() {
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSizeConstraints(
        ImVec2(0, 0), ImVec2(float(fb_width_) - 16.0f, float(fb_height_) - 16.0f));
    ImGui::SetNextWindowBgAlpha(0.85f);
    ImGui::Begin("Settings", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
    // Small windows open the essentials only; every header can be opened by a click.
    const bool roomy = fb_height_ >= 600;
    auto header = [](const char* label, bool open) {
        ImGui::SetNextItemOpen(open, ImGuiCond_FirstUseEver);
        return ImGui::CollapsingHeader(label);
    };
    ImGui::Text("%s backend, %d x %d", GetBackendName().c_str(), fb_width_, fb_height_);
    // Messages wrap at a fixed width: the panel sizes itself to its contents.
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 22.0f);
    if (!status_.empty()) {
        if (status_warning_) ImGui::PushStyleColor(ImGuiCol_Text, kWarning);
        ImGui::TextWrapped("%s", status_.c_str());
        if (status_warning_) ImGui::PopStyleColor();
    }
    if (const auto progress = GetStreamProgress()) {
        const bool warn = progress->starved || !progress->error.empty();
        if (warn) ImGui::PushStyleColor(ImGuiCol_Text, kWarning);
        ImGui::TextWrapped("%s", rendering::FormatStreamProgress(*progress).c_str());
        if (warn) ImGui::PopStyleColor();
    }
    if (open_callback_) {
        ImGui::SetNextItemWidth(ImGui::GetFontSize() * 16.0f);
        const bool enter =
            ImGui::InputTextWithHint("##open", "file to open (or drop one)", open_field_,
                                     sizeof(open_field_), ImGuiInputTextFlags_EnterReturnsTrue);
        ImGui::SameLine();
        if ((ImGui::Button("Open") || enter) && open_field_[0] != '\0') {
            OpenFiles({std::string(open_field_)});
        }
    }
    if (header("Frame", true)) FrameSection(*this);
    if (header("GPU passes", roomy)) GpuSection(*this);
    if (header("Splats", roomy)) SplatSection(*this);
    if (header("Rendering", roomy)) RenderingSection(*this);
    if (header("Objects", true)) ObjectSection(*this);
    if (header("Editing", true)) DrawEditingPanel();
    if (ImGui::Button("Reset camera (R)")) ResetCamera();
    ImGui::SameLine();
    if (ImGui::Button("Screenshot (P)")) RequestScreenshot();
    if (!screenshot_error_.empty()) {
        ImGui::PushStyleColor(ImGuiCol_Text, kWarning);
        ImGui::TextWrapped("%s", screenshot_error_.c_str());
        ImGui::PopStyleColor();
    } else if (!last_screenshot_.empty()) {
        ImGui::Text("Saved %s", std::filesystem::path(last_screenshot_).filename().c_str());
    }
    ImGui::PopTextWrapPos();
    if (header("Controls", false)) {
        ImGui::TextUnformatted(
            "Left drag: orbit\n"
            "Right/middle/shift drag: pan\n"
            "Wheel, +/-: zoom\n"
            "Arrows: orbit (shift: pan)\n"
            "1-9: toggle object\n"
            "Ctrl click: pick, Ctrl drag: select\n"
            "Ctrl+Alt drag: lasso (+Shift: add)\n"
            "Del: delete selected, Ctrl+I: invert\n"
            "Ctrl+Z: undo, K: camera keyframe\n"
            "R: reset camera, P: screenshot\n"
            "H: hide panel, Q/Esc: quit");
    }
    if (panel_callback_) panel_callback_();
    const ImVec2 pos = ImGui::GetWindowPos();
    const ImVec2 size = ImGui::GetWindowSize();
    panel_rect_[0] = pos.x;
    panel_rect_[1] = pos.y;
    panel_rect_[2] = size.x;
    panel_rect_[3] = size.y;
    ImGui::End();
}

}  // namespace visualization
}  // namespace open3d
