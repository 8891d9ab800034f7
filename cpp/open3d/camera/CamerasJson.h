// Reader for the cameras.json file the original 3DGS trainer writes: a list of views with
// id, img_name, width, height, fx, fy, position (camera centre) and rotation (3x3
// camera-to-world, rows as nested lists). The principal point is the image centre.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "open3d/camera/PinholeCamera.h"

namespace open3d {
namespace camera {

/// One entry of a cameras.json file.
struct CameraView {
    int id = 0;
    std::string img_name;
    PinholeCamera camera;
    /// Seconds on a camera path (an optional "time" field, which the 3DGS trainer never
    /// writes; docs/camera-paths.md).
    std::optional<double> time;
};

/// Reads every view, in file order. Throws core::Open3DError naming the file (and the
/// entry index and field) for a missing file, malformed JSON, a missing or mistyped field,
/// a non-positive size or focal length, or a rotation that is not a proper rotation.
std::vector<CameraView> ReadCamerasJson(const std::string& filename);

/// Parses cameras.json text; `source_name` is used in error messages.
std::vector<CameraView> ParseCamerasJson(const std::string& text, const std::string& source_name);

/// cameras.json text of `views`: the fields ParseCamerasJson reads, "time" where set, numbers
/// with enough digits to read back the same doubles. The format has no principal point (the
/// reader puts it at the image centre, ((W - 1) / 2, (H - 1) / 2)): a camera whose principal
/// point is elsewhere is refused, naming its entry.
std::string CamerasJsonText(const std::vector<CameraView>& views);

/// Writes CamerasJsonText(views) to `filename`: to a temporary beside it, then renamed, so
/// a failed write leaves no partial file. Throws core::Open3DError naming the file.
void WriteCamerasJson(const std::string& filename, const std::vector<CameraView>& views);

}  // namespace camera
}  // namespace open3d
