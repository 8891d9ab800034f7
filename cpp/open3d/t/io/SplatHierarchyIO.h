// The level-of-detail hierarchy's file (docs/lod.md "File"): kept next to the scene it was
// built from, written and read bit for bit.
#pragma once

#include <string>

#include "open3d/t/geometry/SplatHierarchy.h"

namespace open3d {
namespace t {
namespace io {

/// Writes `hierarchy` to `filename` (conventionally the scene's name + ".lod"). Throws
/// core::Open3DError naming the file when it cannot be written.
void WriteSplatHierarchy(const std::string& filename, const geometry::SplatHierarchy& hierarchy);

/// Reads a file WriteSplatHierarchy wrote (version 2, with the scene's fingerprint), or a
/// version 1 file (scene_fingerprint 0). Throws core::Open3DError naming the file and the
/// offending field for anything else: another magic or version, sizes that disagree with the
/// file's length, a child id out of range or not below its parent, a node with other than one
/// parent (the root none), an inner node with fewer than 2 or more than 8 children.
geometry::SplatHierarchy ReadSplatHierarchy(const std::string& filename);

}  // namespace io
}  // namespace t
}  // namespace open3d
