#include "open3d/t/io/SplatHierarchyIO.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/t/io/SplatColumns.h"

namespace open3d {
namespace t {
namespace io {

namespace {

static_assert(std::endian::native == std::endian::little,
              "the hierarchy file is little-endian and read by memcpy");

constexpr char kMagic[8] = {'O', '3', 'D', 'G', 'S', 'L', 'O', 'D'};
// Version 2 adds the scene's fingerprint after the counts; version 1 files are still read
// (fingerprint 0: only the leaf count and SH degree can be checked against a scene).
constexpr uint32_t kVersion = 2;
constexpr int kMaxChildren = 8;
constexpr size_t kHeaderBytesV1 = 8 + 4 + 4 + 3 * 8;
constexpr size_t kHeaderBytes = kHeaderBytesV1 + 8;

template <typename T>
void Append(std::vector<uint8_t>& bytes, const T* values, size_t count) {
    const size_t at = bytes.size();
    bytes.resize(at + count * sizeof(T));
    if (count > 0) std::memcpy(bytes.data() + at, values, count * sizeof(T));
}

}  // namespace

void WriteSplatHierarchy(const std::string& filename, const geometry::SplatHierarchy& hierarchy) {
    const int64_t k = hierarchy.NumInner();
    const int degree = k > 0 ? hierarchy.inner.GaussianSplatGetSHOrder() : 0;
    const int64_t counts[] = {hierarchy.num_leaves, k,
                              static_cast<int64_t>(hierarchy.children.size())};
    std::vector<uint8_t> bytes;
    Append(bytes, kMagic, 8);
    Append(bytes, &kVersion, 1);
    const uint32_t sh_degree = static_cast<uint32_t>(degree);
    Append(bytes, &sh_degree, 1);
    Append(bytes, counts, 3);
    Append(bytes, &hierarchy.scene_fingerprint, 1);
    Append(bytes, hierarchy.child_offsets.data(), hierarchy.child_offsets.size());
    Append(bytes, hierarchy.children.data(), hierarchy.children.size());
    if (k > 0) {
        for (const SplatAttribute& a :
             SplatAttributesInFileOrder(geometry::NumSHRestCoeffs(degree))) {
            const core::Tensor& values = hierarchy.inner.GetPointAttr(a.name);
            Append(bytes, values.Data<float>(), static_cast<size_t>(k * a.width));
        }
    }
    WriteFileBytes(filename, bytes);
}

geometry::SplatHierarchy ReadSplatHierarchy(const std::string& filename) {
    const MappedFile file(filename);
    const uint8_t* data = file.data();
    const size_t size = file.size();
    const auto fail = [&](const std::string& why) {
        core::ThrowError("'{}': not a splat hierarchy file written by this version: {}", filename,
                         why);
    };
    if (size < kHeaderBytesV1 || std::memcmp(data, kMagic, 8) != 0) {
        fail("it does not start with the magic 'O3DGSLOD' and a full header");
    }
    uint32_t version = 0, sh_degree = 0;
    int64_t counts[3] = {0, 0, 0};
    std::memcpy(&version, data + 8, 4);
    std::memcpy(&sh_degree, data + 12, 4);
    std::memcpy(counts, data + 16, 24);
    if (version != 1 && version != kVersion) {
        fail("version " + std::to_string(version) + ", not 1 or 2");
    }
    const size_t header_bytes = version == 1 ? kHeaderBytesV1 : kHeaderBytes;
    if (size < header_bytes) fail("it ends inside its header");
    uint64_t fingerprint = 0;
    if (version >= 2) std::memcpy(&fingerprint, data + kHeaderBytesV1, 8);
    if (sh_degree > 3) fail("sh_degree " + std::to_string(sh_degree) + " (0..3)");
    const int64_t leaves = counts[0], inner = counts[1], links = counts[2];
    // Every count bounded by the file before any product is formed.
    const int64_t limit = static_cast<int64_t>(size / 4);
    if (leaves < 1 || inner < 0 || inner > limit || links < 0 || links > limit ||
        leaves > links + 1) {
        fail("counts leaves " + std::to_string(leaves) + ", inner " + std::to_string(inner) +
             ", children " + std::to_string(links) + " do not fit a file of " +
             std::to_string(size) + " bytes");
    }
    const int num_rest = geometry::NumSHRestCoeffs(static_cast<int>(sh_degree));
    int64_t floats_per_node = 0;
    for (const SplatAttribute& a : SplatAttributesInFileOrder(num_rest)) floats_per_node += a.width;
    const uint64_t expected = header_bytes + 8 * uint64_t(inner + 1) + 8 * uint64_t(links) +
                              4 * uint64_t(inner) * uint64_t(floats_per_node);
    if (expected != size) {
        fail("the counts need " + std::to_string(expected) + " bytes, the file has " +
             std::to_string(size));
    }

    geometry::SplatHierarchy h;
    h.num_leaves = leaves;
    h.scene_fingerprint = fingerprint;
    h.child_offsets = std::vector<int64_t>(static_cast<size_t>(inner + 1));
    h.children = std::vector<int64_t>(static_cast<size_t>(links));
    const uint8_t* at = data + header_bytes;
    std::memcpy(h.child_offsets.data(), at, 8 * (inner + 1));
    at += 8 * (inner + 1);
    if (links > 0) std::memcpy(h.children.data(), at, 8 * links);
    at += 8 * links;

    if (h.child_offsets[0] != 0 || h.child_offsets[inner] != links) {
        fail("child_offsets must run from 0 to the number of children");
    }
    if (inner == 0 && leaves != 1) fail("a hierarchy of several leaves needs inner nodes");
    // Every node's child count is checked before any child is read: a count that fits
    // 2..8 can still run past the children when a later offset steps back.
    for (int64_t k = 0; k < inner; ++k) {
        const int64_t count = h.child_offsets[k + 1] - h.child_offsets[k];
        if (count < 2 || count > kMaxChildren) {
            fail("inner node " + std::to_string(k) + " has " + std::to_string(count) +
                 " children (2..8)");
        }
    }
    std::vector<uint8_t> parents(leaves + inner, 0);
    for (int64_t k = 0; k < inner; ++k) {
        for (int64_t c = h.child_offsets[k]; c < h.child_offsets[k + 1]; ++c) {
            const int64_t child = h.children[c];
            if (child < 0 || child >= leaves + k) {
                fail("child " + std::to_string(child) + " of inner node " + std::to_string(k) +
                     " is not a node built before it");
            }
            if (++parents[child] > 1) fail("node " + std::to_string(child) + " has two parents");
        }
    }
    for (int64_t node = 0; node + 1 < leaves + inner; ++node) {
        if (parents[node] != 1) fail("node " + std::to_string(node) + " has no parent");
    }

    if (inner > 0) {
        h.inner = ReadSplatAttributeBlocks(at, inner, num_rest, [&](const char* name, int64_t row) {
            fail(std::string("a non-finite ") + name + " of inner node " + std::to_string(row));
        });
    }
    return h;
}

}  // namespace io
}  // namespace t
}  // namespace open3d
