// Internal to t/io: Gaussian attributes as flat columns while a reader fills them, and
// the shared checks every format applies before a cloud is handed out.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/io/PointCloudIO.h"

namespace open3d {
namespace t {
namespace io {

/// Throws (core::RequireHostMemory) unless n splats of the given kind fit in host memory
/// with `extra_per_splat` more bytes each (e.g. the decoded streams a reader holds while it
/// fills the columns; named by `extra_what`). SplatColumns::Allocate checks with 0; a reader
/// of a compressed format calls it before decompressing. n is at most 2^32 here.
void CheckSplatColumnsMemory(const std::string& filename, int64_t n, bool gaussian, int degree,
                             uint64_t extra_per_splat, const std::string& extra_what);

struct SplatColumns {
    int64_t num_points = 0;
    bool is_gaussian = false;
    int sh_degree = 0;
    // Readers write straight into the tensors the cloud will own (no extra copy).
    core::Tensor positions;  // [N, 3]
    core::Tensor scale;      // [N, 3] linear
    core::Tensor rot;        // [N, 4] (w, x, y, z), normalised by FinalizeColumns
    core::Tensor opacity;    // [N, 1] logit
    core::Tensor f_dc;       // [N, 3]
    core::Tensor f_rest;     // [N, Nc, 3]

    /// Sizes every column for n points, uninitialised (positions only when !gaussian).
    /// Throws naming `filename`, the bytes needed and the splat count that would fit when
    /// the columns need more than the available host memory (core::RequireHostMemory).
    void Allocate(const std::string& filename, int64_t n, bool gaussian, int degree);
};

/// A read-only view of a whole file (memory-mapped). Throws naming the file when it
/// cannot be opened or mapped, or when it is empty. `populate` reads the whole file in at
/// once (readers of whole files); without it the pages are read when first touched (the
/// streaming of SplatPageFile, which reads a page of the scene at a time).
class MappedFile {
public:
    explicit MappedFile(const std::string& filename, bool populate = true);
    ~MappedFile();
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;

    const uint8_t* data() const { return data_; }
    size_t size() const { return size_; }

private:
    const uint8_t* data_ = nullptr;
    size_t size_ = 0;
};

/// A Gaussian attribute as the hierarchy's files store it (SplatHierarchyIO, SplatPageFile):
/// its name and float32 values per splat, a block of all the splats' rows per attribute.
struct SplatAttribute {
    const char* name;
    int64_t width;
};
/// The blocks in file order: positions 3, scale 3, rot 4, opacity 1, f_dc 3, then f_rest
/// 3 x num_rest where num_rest > 0.
std::vector<SplatAttribute> SplatAttributesInFileOrder(int num_rest);

/// The splat cloud of `n` splats whose attribute blocks (SplatAttributesInFileOrder) start at
/// `at`; `non_finite(name, row)` is called for the first NaN or infinite value and must throw.
geometry::PointCloud ReadSplatAttributeBlocks(
    const uint8_t* at, int64_t n, int num_rest,
    const std::function<void(const char* name, int64_t row)>& non_finite);

/// Writes bytes to a file, throwing with the file name on failure.
void WriteFileBytes(const std::string& filename, const std::vector<uint8_t>& bytes);

/// Normalises quaternions (zero -> error with the splat index), refuses or drops
/// non-finite splats (the error names the first offending attribute and splat index),
/// and builds the cloud. Frees the columns as it goes.
geometry::PointCloud FinalizeColumns(const std::string& filename, SplatColumns& columns,
                                     const ReadPointCloudOptions& options,
                                     ReadPointCloudReport& report);

}  // namespace io
}  // namespace t
}  // namespace open3d
