#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStageResources.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>

#include "GaussianSplatProjectionContract.h"
#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/RadixSort.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

constexpr VkBufferUsageFlags kTransfer =
    VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

}  // namespace

namespace {

// Every scene and per-view buffer here but the shape and SH words and the projected records
// (read through device addresses) is bound whole as one storage binding. A range past the
// device's maxStorageBufferRange is invalid usage that only the validation layer reports;
// without it the H200's driver read zeros past the limit (a 5.9 GB shape buffer of 147M
// hierarchy nodes, when it was bound: garbage footprints, 134M tile entries for 2M visible
// splats).
void RequireStorageBinding(const VulkanContext& context, const char* what, VkDeviceSize bytes,
                           uint64_t count) {
    const uint64_t limit = context.GetDeviceInfo().max_storage_buffer_range;
    if (bytes > limit) {
        core::ThrowError(
            "Vulkan backend: the {} for {} splats take {} bytes, more than one storage binding "
            "of this device holds ({} bytes, maxStorageBufferRange); fewer splats fit",
            what, count, bytes, limit);
    }
}

constexpr VkBufferUsageFlags kAddressed = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

}  // namespace

Buffer UploadStorageBuffer(const VulkanContext& context, const CommandPool& pool, const void* data,
                           VkDeviceSize bytes, VkBufferUsageFlags extra_usage) {
    return UploadStorageBuffer(
        context, pool, bytes,
        [&](uint8_t* staging) {
            if (bytes > 0) std::memcpy(staging, data, bytes);
        },
        extra_usage);
}

Buffer UploadStorageBuffer(const VulkanContext& context, const CommandPool& pool,
                           VkDeviceSize bytes, const std::function<void(uint8_t*)>& fill,
                           VkBufferUsageFlags extra_usage) {
    const VkDeviceSize size = std::max<VkDeviceSize>(bytes, 16);
    Buffer device(context, size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | kTransfer | extra_usage,
                  MemoryUsage::kDevice);
    Buffer staging(context, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::kHostUpload);
    std::memset(staging.GetMapped(), 0, size);
    fill(static_cast<uint8_t*>(staging.GetMapped()));
    SubmitAndWait(context, pool, [&](VkCommandBuffer cmd) {
        const VkBufferCopy region{0, 0, size};
        vkCmdCopyBuffer(cmd, staging.Get(), device.Get(), 1, &region);
    });
    return device;
}

void GeometryStageResources::UploadScene(const VulkanContext& context, const CommandPool& pool,
                                         const PackedGaussianSplats& packed) {
    // The positions, shape and SH words are read by device address, so no binding's range
    // limits the splats (a hierarchy's cut binds its nodes' positions: UploadLod checks its
    // nodes, 16 bytes each as a position). The visibility mask (4 bytes per 32 splats) is bound.
    positions = UploadStorageBuffer(context, pool, packed.positions.data(),
                                    packed.positions.size() * sizeof(float), kAddressed);
    shape = UploadStorageBuffer(context, pool, packed.shape.data(), packed.shape.size() * 4,
                                kAddressed);
    sh = UploadStorageBuffer(context, pool, packed.sh.data(), packed.sh.size() * 4, kAddressed);
    visibility =
        UploadStorageBuffer(context, pool, packed.visibility.data(), packed.visibility.size() * 4);
    scene_bytes_ = (packed.positions.size() + packed.shape.size() + packed.sh.size() +
                    packed.visibility.size()) *
                   4;
    SetLayout(packed, packed.num_splats);
}

void GeometryStageResources::UploadSceneInParts(const VulkanContext& context,
                                                const CommandPool& pool,
                                                const t::geometry::PointCloud& cloud,
                                                SplatPrecision precision,
                                                const std::vector<uint32_t>& mask) {
    const t::geometry::GaussianSplatArrays arrays = cloud.GetGaussianSplatArrays();  // validates
    const int64_t n = arrays.num_points;
    if (n > static_cast<int64_t>(std::numeric_limits<uint32_t>::max())) {
        core::ThrowError("uploading {} splats: at most 2^32 - 1 fit a splat index", n);
    }
    AllocateScene(context, pool, PackedSplatLayout(arrays.sh_degree, precision), n);
    // One staging buffer for a submission's parts: its positions, then shape, then SH words.
    const int64_t per_submission = std::min(n, kUploadPartSplats * kUploadPartsPerSubmission);
    const VkDeviceSize position_bytes = 4 * sizeof(float);
    const VkDeviceSize shape_bytes = layout_.shape_words_per_splat * 4;
    const VkDeviceSize sh_bytes = layout_.sh_words_per_splat * 4;
    const VkDeviceSize splat_bytes = position_bytes + shape_bytes + sh_bytes;
    Buffer staging(context, std::max<VkDeviceSize>(per_submission * splat_bytes, 16),
                   VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::kHostUpload);
    auto* bytes = static_cast<uint8_t*>(staging.GetMapped());
    for (int64_t first = 0; first < n; first += per_submission) {
        const int64_t count = std::min(per_submission, n - first);
        const VkDeviceSize shape_base = count * position_bytes;
        const VkDeviceSize sh_base = shape_base + count * shape_bytes;
        const int64_t parts = (count + kUploadPartSplats - 1) / kUploadPartSplats;
        std::vector<Eigen::Vector3d> mins(parts, layout_.center_min),
            maxs(parts, layout_.center_max);
        core::ParallelFor(
            parts,
            [&](int64_t k) {
                const int64_t offset = k * kUploadPartSplats;
                const int64_t end = std::min(offset + kUploadPartSplats, count);
                PackGaussianSplatRangeInto(
                    cloud, first + offset, first + end, layout_,
                    {reinterpret_cast<float*>(bytes + offset * position_bytes),
                     reinterpret_cast<uint32_t*>(bytes + shape_base + offset * shape_bytes),
                     reinterpret_cast<uint32_t*>(bytes + sh_base + offset * sh_bytes)},
                    mins[size_t(k)], maxs[size_t(k)]);
            },
            1);
        for (int64_t k = 0; k < parts; ++k) {
            layout_.center_min = layout_.center_min.cwiseMin(mins[size_t(k)]);
            layout_.center_max = layout_.center_max.cwiseMax(maxs[size_t(k)]);
        }
        SubmitAndWait(context, pool, [&](VkCommandBuffer cmd) {
            const VkDeviceSize at = static_cast<VkDeviceSize>(first);
            const VkBufferCopy to_positions{0, at * position_bytes, count * position_bytes};
            const VkBufferCopy to_shape{shape_base, at * shape_bytes, count * shape_bytes};
            vkCmdCopyBuffer(cmd, staging.Get(), positions.Get(), 1, &to_positions);
            vkCmdCopyBuffer(cmd, staging.Get(), shape.Get(), 1, &to_shape);
            if (sh_bytes > 0) {
                const VkBufferCopy to_sh{sh_base, at * sh_bytes, count * sh_bytes};
                vkCmdCopyBuffer(cmd, staging.Get(), sh.Get(), 1, &to_sh);
            }
        });
    }
    if (mask.empty()) {
        std::vector<uint32_t> shown((static_cast<size_t>(n) + 31) / 32, 0u);
        SetSplatVisibility(shown, 0, n, true);
        UploadVisibility(context, pool, shown);
    } else {
        UploadVisibility(context, pool, mask);
    }
}

void GeometryStageResources::SetLayout(const PackedGaussianSplats& like, int64_t num_splats) {
    layout_.precision = like.precision;
    layout_.num_splats = num_splats;
    layout_.sh_degree = like.sh_degree;
    layout_.shape_words_per_splat = like.shape_words_per_splat;
    layout_.sh_words_per_splat = like.sh_words_per_splat;
    layout_.center_min = like.center_min;
    layout_.center_max = like.center_max;
    // The per-view buffers are sized for a splat count: a new scene needs new ones.
    view_ = GeometryStageViewResources();
    write_staging_ = Buffer();
}

void GeometryStageResources::AllocateScene(const VulkanContext& context, const CommandPool& pool,
                                           const PackedGaussianSplats& like, int64_t capacity) {
    const uint64_t n = static_cast<uint64_t>(capacity);
    const auto zeroed = [&](VkDeviceSize bytes, VkBufferUsageFlags extra_usage) {
        Buffer device(context, std::max<VkDeviceSize>(bytes, 16),
                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | kTransfer | extra_usage,
                      MemoryUsage::kDevice);
        SubmitAndWait(context, pool, [&](VkCommandBuffer cmd) {
            vkCmdFillBuffer(cmd, device.Get(), 0, VK_WHOLE_SIZE, 0u);
        });
        return device;
    };
    const VkDeviceSize visibility_bytes = (n + 31) / 32 * 4;
    RequireStorageBinding(context, "visibility", visibility_bytes, n);
    positions = zeroed(n * 4 * sizeof(float), kAddressed);
    shape = zeroed(n * like.shape_words_per_splat * 4, kAddressed);
    sh = zeroed(n * like.sh_words_per_splat * 4, kAddressed);
    visibility = zeroed(visibility_bytes, 0);
    scene_bytes_ =
        n * (4 * sizeof(float) + 4 * like.shape_words_per_splat + 4 * like.sh_words_per_splat) +
        visibility_bytes;
    SetLayout(like, capacity);
}

void GeometryStageResources::WriteSplats(
    const VulkanContext& context, const CommandPool& pool,
    const std::vector<std::pair<int64_t, const t::geometry::PointCloud*>>& parts) {
    // Each part's place in the staging buffer: its positions, shape and SH words in turn.
    struct Place {
        VkDeviceSize positions = 0, shape = 0, sh = 0;
        Eigen::Vector3d center_min =
            Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
        Eigen::Vector3d center_max = -center_min;
    };
    std::vector<Place> places(parts.size());
    VkDeviceSize total = 0;
    for (size_t i = 0; i < parts.size(); ++i) {
        const auto& [first, cloud] = parts[i];
        const int64_t n = cloud->NumPoints();
        if (cloud->GetGaussianSplatArrays().sh_degree != layout_.sh_degree) {
            core::ThrowError("writing splats of SH degree {} into a scene packed at {}",
                             cloud->GetGaussianSplatArrays().sh_degree, layout_.sh_degree);
        }
        if (first < 0 || first + n > layout_.num_splats) {
            core::ThrowError("writing splats [{}, {}) into a scene of {} splats", first, first + n,
                             layout_.num_splats);
        }
        const VkDeviceSize splats = static_cast<VkDeviceSize>(n);
        places[i].positions = total;
        total += splats * 4 * sizeof(float);
        places[i].shape = total;
        total += splats * layout_.shape_words_per_splat * 4;
        places[i].sh = total;
        total += splats * layout_.sh_words_per_splat * 4;
    }
    if (total == 0) return;
    if (!write_staging_ || write_staging_.GetSize() < total) {
        write_staging_ = Buffer();  // the old one goes first: host memory is the limit
        write_staging_ =
            Buffer(context, total, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::kHostUpload);
    }
    auto* bytes = static_cast<uint8_t*>(write_staging_.GetMapped());
    // A part per task: a streaming step writes 16 pages of 65,536 splats by default.
    core::ParallelFor(
        static_cast<int64_t>(parts.size()),
        [&](int64_t i) {
            Place& place = places[size_t(i)];
            PackGaussianSplatAttrsInto(*parts[size_t(i)].second, layout_,
                                       {reinterpret_cast<float*>(bytes + place.positions),
                                        reinterpret_cast<uint32_t*>(bytes + place.shape),
                                        reinterpret_cast<uint32_t*>(bytes + place.sh)},
                                       place.center_min, place.center_max);
        },
        1);
    std::vector<VkBufferCopy> to_positions, to_shape, to_sh;
    for (size_t i = 0; i < parts.size(); ++i) {
        const VkDeviceSize first = static_cast<VkDeviceSize>(parts[i].first);
        const VkDeviceSize n = static_cast<VkDeviceSize>(parts[i].second->NumPoints());
        if (n == 0) continue;
        to_positions.push_back(
            {places[i].positions, first * 4 * sizeof(float), n * 4 * sizeof(float)});
        to_shape.push_back({places[i].shape, first * layout_.shape_words_per_splat * 4,
                            n * layout_.shape_words_per_splat * 4});
        if (layout_.sh_words_per_splat > 0) {
            to_sh.push_back({places[i].sh, first * layout_.sh_words_per_splat * 4,
                             n * layout_.sh_words_per_splat * 4});
        }
        layout_.center_min = layout_.center_min.cwiseMin(places[i].center_min);
        layout_.center_max = layout_.center_max.cwiseMax(places[i].center_max);
    }
    SubmitAndWait(context, pool, [&](VkCommandBuffer cmd) {
        for (const auto& [buffer, regions] :
             {std::pair{&positions, &to_positions}, {&shape, &to_shape}, {&sh, &to_sh}}) {
            if (regions->empty()) continue;
            vkCmdCopyBuffer(cmd, write_staging_.Get(), buffer->Get(), uint32_t(regions->size()),
                            regions->data());
        }
    });
}

void GeometryStageResources::UploadLod(const VulkanContext& context, const CommandPool& pool,
                                       const PackedLodNodes& lod) {
    if (int64_t(lod.num_leaves) + lod.num_inner != layout_.num_splats) {
        core::ThrowError("a hierarchy of {} + {} nodes for a scene of {} splats", lod.num_leaves,
                         lod.num_inner, layout_.num_splats);
    }
    // One buffer: the nodes, then their children from an offset every device can bind at.
    const VkDeviceSize node_bytes = lod.nodes.size() * sizeof(shader::GaussianLodNode);
    const VkDeviceSize alignment =
        std::max<VkDeviceSize>(context.GetDeviceInfo().min_storage_buffer_offset_alignment, 16);
    const VkDeviceSize children_offset = (node_bytes + alignment - 1) / alignment * alignment;
    const VkDeviceSize children_bytes = std::max<VkDeviceSize>(lod.children.size() * 4, 4);
    // Then one word the cut's walk writes (its last threshold), zero from the staging memory.
    const VkDeviceSize previous_offset =
        (children_offset + children_bytes + alignment - 1) / alignment * alignment;
    RequireStorageBinding(context, "hierarchy nodes", node_bytes, lod.nodes.size());
    // The cut binds the nodes' positions too (the projection reads them by address).
    RequireStorageBinding(context, "positions of the hierarchy's nodes",
                          VkDeviceSize(layout_.num_splats) * 4 * sizeof(float), lod.nodes.size());
    RequireStorageBinding(context, "hierarchy children", children_bytes, lod.nodes.size());
    lod_nodes = UploadStorageBuffer(context, pool, previous_offset + 4, [&](uint8_t* staging) {
        std::memcpy(staging, lod.nodes.data(), node_bytes);
        if (lod.children.empty()) return;  // one leaf
        std::memcpy(staging + children_offset, lod.children.data(), lod.children.size() * 4);
    });
    lod_nodes_bytes_ = node_bytes;
    lod_children_offset_ = children_offset;
    lod_children_bytes_ = children_bytes;
    lod_previous_offset_ = previous_offset;
    lod_leaves_ = lod.num_leaves;
    lod_inner_ = lod.num_inner;
    lod_inner_levels_ = lod.inner_levels;
    view_ = GeometryStageViewResources();  // the view needs the cut's buffers
}

void GeometryStageResources::ClearLod() {
    lod_nodes = Buffer();
    lod_leaves_ = lod_inner_ = lod_inner_levels_ = 0;
}

void GeometryStageResources::UploadVisibility(const VulkanContext& context, const CommandPool& pool,
                                              const std::vector<uint32_t>& mask) {
    const size_t words = (static_cast<size_t>(layout_.num_splats) + 31) / 32;
    if (mask.size() != words) {
        core::ThrowError("visibility mask has {} words, the scene of {} splats needs {}",
                         mask.size(), layout_.num_splats, words);
    }
    visibility = UploadStorageBuffer(context, pool, mask.data(), mask.size() * 4);
}

void GeometryStageResources::AllocateView(const VulkanContext& context, uint32_t entry_capacity) {
    view_.Allocate(context, static_cast<uint32_t>(layout_.num_splats), entry_capacity, LodInner());
}

void GeometryStageViewResources::Allocate(const VulkanContext& context, uint32_t n,
                                          uint32_t entry_capacity,
                                          std::optional<uint32_t> lod_inner) {
    // A hierarchy's frame runs over its cut's list, at most a slot per leaf (LodListSlots):
    // the buffers after the cut are sized for the leaves, not the nodes.
    if (lod_inner && *lod_inner >= n) {
        core::ThrowError("GeometryStageViewResources: {} inner nodes of {} nodes", *lod_inner, n);
    }
    const uint32_t slots = lod_inner ? n - *lod_inner : n;
    // The depth sort takes the slots, the tile sort the entries: both within what this
    // device's bindings reach (1.07G pairs on an H200, 33.5M on lavapipe). The per-splat and
    // per-node passes lay their workgroups out in rows (DispatchGridFor), so
    // maxComputeWorkGroupCount bounds none of them.
    const VulkanDeviceInfo& info = context.GetDeviceInfo();
    const uint32_t sort_limit = RadixSort::MaxCountFor(info);
    if (slots > sort_limit || entry_capacity > sort_limit) {
        core::ThrowError(
            "GeometryStageViewResources: {} slots / {} tile entries exceed the sort limit of "
            "this device, {} pairs (maxStorageBufferRange {} bytes)",
            slots, entry_capacity, sort_limit, info.max_storage_buffer_range);
    }
    const GeometryStageStorageRequirements need =
        GaussianGeometryStage::GetStorageRequirements(slots, entry_capacity);
    const auto make = [&](VkDeviceSize bytes, VkBufferUsageFlags usage) {
        if (!(usage & kAddressed)) RequireStorageBinding(context, "per-view buffers", bytes, slots);
        return Buffer(context, std::max<VkDeviceSize>(bytes, 16), usage | kTransfer,
                      MemoryUsage::kDevice);
    };
    view_params = make(need.view_params_bytes, need.view_params_usage);
    counters = make(need.counters_bytes, need.counters_usage);
    depth_keys = make(need.depth_keys_bytes, need.usage);
    splat_indices = make(need.splat_indices_bytes, need.usage);
    tile_counts = make(need.tile_counts_bytes, need.usage);
    scan = make(need.scan_bytes, need.usage);
    entry_keys = make(need.entry_keys_bytes, need.usage);
    entry_values = make(need.entry_values_bytes, need.usage);
    keys_alt = make(need.sort.keys_alt_bytes, need.sort.scratch_usage);
    values_alt = make(need.sort.values_alt_bytes, need.sort.scratch_usage);
    histogram = make(need.sort.histogram_bytes, need.sort.scratch_usage);
    sort_params = make(need.sort.params_bytes, need.sort.params_usage);
    depth_sweep_state = make(need.sort.sweep_state_bytes, need.sort.sweep_state_usage);
    tile_sweep_state = make(need.sort.sweep_state_bytes, need.sort.sweep_state_usage);
    lod_buckets = Buffer();
    lod_histogram = Buffer();
    lod_visibility = Buffer();
    lod_group_counts = Buffer();
    lod_list = Buffer();
    lod_walk = Buffer();
    if (lod_inner) {
        lod_buckets = make(GaussianLodCut::BucketsBytes(*lod_inner), need.usage);
        lod_histogram = make(GaussianLodCut::HistogramBytes(), need.usage);
        lod_visibility = make(GaussianLodCut::VisibilityBytes(n), need.usage);
        lod_group_counts = make(GaussianLodCut::GroupCountsBytes(n), need.usage);
        lod_list = make(GaussianLodCut::ListBytes(slots), need.usage);
        lod_walk = make(GaussianLodCut::WalkBytes(*lod_inner),
                        need.usage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    }
    // The largest, and the one not bound: made after every bound buffer has passed its check.
    projected = make(need.projected_bytes, need.usage | kAddressed);
    lod_inner_ = lod_inner;
    num_splats_ = n;
    entry_capacity_ = entry_capacity;
}

GeometryStageSceneBuffers GeometryStageResources::Scene() const {
    GeometryStageSceneBuffers scene;
    scene.positions = positions.Range();
    scene.shape = shape.Range();
    scene.sh = sh.Range();
    scene.visibility = visibility.Range();
    scene.lod = HasLod();
    if (scene.lod) {
        scene.lod_nodes = lod_nodes.Range(0, lod_nodes_bytes_);
        scene.lod_children = lod_nodes.Range(lod_children_offset_, lod_children_bytes_);
        scene.lod_previous = lod_nodes.Range(lod_previous_offset_, 4);
        scene.lod_leaves = lod_leaves_;
        scene.lod_inner = lod_inner_;
        scene.lod_inner_levels = lod_inner_levels_;
    }
    scene.num_splats = static_cast<uint32_t>(layout_.num_splats);
    scene.packed_sh_degree = layout_.sh_degree;
    scene.sh_words_per_splat = layout_.sh_words_per_splat;
    scene.precision = layout_.precision;
    return scene;
}

GeometryStageViewBuffers GeometryStageResources::View() const { return view_.Buffers(); }

GeometryStageViewBuffers GeometryStageViewResources::Buffers() const {
    GeometryStageViewBuffers view;
    view.view_params = view_params.Range();
    view.projected = projected.Range();
    view.counters = counters.Range();
    view.depth_keys = depth_keys.Range();
    view.splat_indices = splat_indices.Range();
    view.tile_counts = tile_counts.Range();
    view.scan = scan.Range();
    view.entry_keys = entry_keys.Range();
    view.entry_values = entry_values.Range();
    view.sort_scratch = {keys_alt.Range(), values_alt.Range(), histogram.Range(),
                         sort_params.Range(), depth_sweep_state.Range()};
    view.tile_sort_sweep_state = tile_sweep_state.Range();
    if (lod_inner_) {
        view.lod_buckets = lod_buckets.Range();
        view.lod_histogram = lod_histogram.Range();
        view.lod_visibility = lod_visibility.Range();
        view.lod_group_counts = lod_group_counts.Range();
        view.lod_list = lod_list.Range();
        view.lod_walk = lod_walk.Range();
    }
    return view;
}

PackedView GeometryStageResources::ViewParams(const camera::PinholeCamera& camera,
                                              const RenderConfig& config) const {
    return ViewParams(camera, config, view_.EntryCapacity());
}

PackedView GeometryStageResources::ViewParams(const camera::PinholeCamera& camera,
                                              const RenderConfig& config,
                                              uint32_t entry_capacity) const {
    ViewPackingInputs inputs;
    // A hierarchy's frame runs over the slots of its cut's list, not over every node.
    inputs.num_splats =
        HasLod() ? shader::LodListSlots(lod_leaves_, PackedLodBudget(config)) : layout_.num_splats;
    inputs.packed_sh_degree = layout_.sh_degree;
    inputs.precision = layout_.precision;
    inputs.sh_words_per_splat = layout_.sh_words_per_splat;
    inputs.entry_capacity = entry_capacity;
    inputs.center_min = layout_.center_min;
    inputs.center_max = layout_.center_max;
    return PackGaussianView(camera, config, inputs);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
