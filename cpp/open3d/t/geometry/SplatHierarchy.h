// A level-of-detail hierarchy over a Gaussian splat cloud (docs/lod.md): an octree over the
// splats' positions whose inner nodes are Gaussians merged from their children by moment
// matching, and the cut that picks, for one view, the nodes to draw under a splat budget.
// The file is t/io/SplatHierarchyIO.h; the cut the Vulkan renderer chooses per frame on the
// GPU is a threshold cut of its own (visualization/.../cpu/LodCut.h mirrors it).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace t {
namespace geometry {

/// Node ids: node i < num_leaves is splat i of the source cloud; inner node k is node
/// num_leaves + k, row k of `inner`; the root is the last node (the only leaf of a cloud of
/// one splat). Every inner node has 2 to 8 children.
struct SplatHierarchy {
    int64_t num_leaves = 0;
    /// SplatSceneFingerprint of the cloud it was built from (0: unknown, a file of version
    /// 1): a hierarchy file left beside a scene that changed since is recognised by it.
    uint64_t scene_fingerprint = 0;
    /// The inner nodes' Gaussians, with the source's attributes (positions, scale, rot,
    /// opacity, f_dc and f_rest when the source has it).
    PointCloud inner;
    /// Children of inner node k: children[child_offsets[k] .. child_offsets[k + 1]).
    std::vector<int64_t> child_offsets{0};
    std::vector<int64_t> children;

    int64_t NumInner() const { return static_cast<int64_t>(child_offsets.size()) - 1; }
    int64_t NumNodes() const { return num_leaves + NumInner(); }
    int64_t Root() const { return NumNodes() - 1; }
};

/// A 64-bit hash of a splat cloud's count, SH degree, positions and opacities: what tells a
/// hierarchy built from this cloud from one built from another (docs/lod.md "File").
uint64_t SplatSceneFingerprint(const PointCloud& splats);

/// Why `hierarchy` cannot have been built from `source` (its leaf count, its inner nodes'
/// SH degree, or a known fingerprint differs), or "" when it fits. ExtractSplatNodes and the
/// renderers refuse a hierarchy that does not fit; tools name the files with the reason.
std::string HierarchySourceMismatch(const SplatHierarchy& hierarchy, const PointCloud& source);

/// Builds the hierarchy of a valid, non-empty splat cloud. The octree splits the cloud's
/// bounding cube by the splats' Morton codes (21 bits per axis); a cell with one occupied
/// child is skipped, and splats that share a code are grouped eight at a time. An inner
/// node's Gaussian matches the opacity- and volume-weighted moments of its children (mean,
/// covariance including the spread of their means; colour and SH weighted alike); its
/// opacity is 1 - prod(1 - alpha_c * min(1, a_c b_c / (a b))), a and b the two largest scales,
/// so stacked copies compose like layers and small children cover their share of the node.
/// Throws core::Open3DError for an empty or invalid cloud.
SplatHierarchy BuildSplatHierarchy(const PointCloud& splats);

/// The camera a cut is chosen for: p_cam = R p_world + t from world_to_camera, focal length
/// in pixels (the larger of fx and fy), and, where width > 0, the image whose frustum bounds
/// what the cut refines (pinhole fx, fy, cx, cy in pixels, OpenCV axes: z forward).
struct SplatCutView {
    Eigen::Matrix4d world_to_camera = Eigen::Matrix4d::Identity();
    double focal_px = 1.0;
    int width = 0, height = 0;  ///< 0: no frustum test beyond the camera's back
    double fx = 1.0, fy = 1.0, cx = 0.0, cy = 0.0;
};

/// Whether a sphere of `radius` about camera-space point `c` lies wholly behind the camera or,
/// where `view` has an image, wholly outside one of its frustum's four side planes widened
/// like the renderer's guard band (docs/lod.md "Cut"): nothing inside it can colour a pixel.
bool SplatOutsideView(const SplatCutView& view, const Eigen::Vector3d& c, double radius);

/// A cut of at most `budget` (>= 1) nodes, every leaf under exactly one of them, in ascending
/// node id. From the root, the node of largest projected size (focal_px * 3 * largest scale /
/// depth, nodes nearer than their own size first) is replaced by its children while that
/// keeps the cut within the budget; a node whose children do not fit stays whole. Nodes whose
/// bounding sphere (3 x the largest scale) lies wholly behind the camera or, with the view's
/// image, outside its frustum (with a guard band) are opened only after every node in view:
/// the budget goes to what the view sees. A budget of at least num_leaves gives every leaf:
/// the source cloud itself.
std::vector<int64_t> CutSplatHierarchy(const SplatHierarchy& hierarchy, const SplatCutView& view,
                                       int64_t budget);

/// The splats of `nodes` (ids of `hierarchy`, built from `source`), in that order.
PointCloud ExtractSplatNodes(const SplatHierarchy& hierarchy, const PointCloud& source,
                             const std::vector<int64_t>& nodes);

}  // namespace geometry
}  // namespace t
}  // namespace open3d
