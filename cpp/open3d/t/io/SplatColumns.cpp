#include "open3d/t/io/SplatColumns.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include <fmt/format.h>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Progress.h"
#include "open3d/core/RegularFile.h"

namespace open3d {
namespace t {
namespace io {

using geometry::NumSHRestCoeffs;

void CheckSplatColumnsMemory(const std::string& filename, int64_t n, bool gaussian, int degree,
                             uint64_t extra_per_splat, const std::string& extra_what) {
    // Checked before the first byte is taken: a 1e8-splat file once grew past 18 GB of
    // resident memory before the kernel killed the process.
    const uint64_t columns_per_point =
        sizeof(float) * (gaussian ? 3 + 3 + 4 + 1 + 3 + 3 * NumSHRestCoeffs(degree) : 3);
    const uint64_t per_point = columns_per_point + extra_per_splat;
    const uint64_t available = core::AvailableHostMemory();
    if (uint64_t(n) > available / per_point) {
        const std::string what =
            extra_per_splat == 0
                ? fmt::format("'{}': {} splats of SH degree {}", filename, n, degree)
                : fmt::format("'{}': {} splats of SH degree {} and {} {}", filename, n, degree,
                              uint64_t(n) * extra_per_splat, extra_what);
        const uint64_t sh0_per_point = sizeof(float) * 14 + extra_per_splat;
        core::RequireHostMemory(
            uint64_t(n) * per_point, what,
            degree > 0 && gaussian
                ? fmt::format("at most {} splats of this degree fit ({} of SH degree 0)",
                              available / per_point, available / sh0_per_point)
                : fmt::format("at most {} splats fit", available / per_point));
    }
}

void SplatColumns::Allocate(const std::string& filename, int64_t n, bool gaussian, int degree) {
    using core::Dtype;
    using core::Tensor;
    CheckSplatColumnsMemory(filename, n, gaussian, degree, 0, "");
    num_points = n;
    is_gaussian = gaussian;
    sh_degree = degree;
    positions = Tensor::Empty({n, 3}, Dtype::Float32);
    if (!gaussian) return;
    scale = Tensor::Empty({n, 3}, Dtype::Float32);
    rot = Tensor::Empty({n, 4}, Dtype::Float32);
    opacity = Tensor::Empty({n, 1}, Dtype::Float32);
    f_dc = Tensor::Empty({n, 3}, Dtype::Float32);
    f_rest = Tensor::Empty({n, NumSHRestCoeffs(degree), 3}, Dtype::Float32);
}

MappedFile::MappedFile(const std::string& filename, bool populate) {
    core::RequireRegularFile(filename);  // before open(), which blocks on a FIFO
    const int fd = ::open(filename.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        core::ThrowError("Cannot open '{}' for reading: {}", filename, std::strerror(errno));
    struct stat info;
    if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
        ::close(fd);
        core::ThrowError("Cannot read '{}': not a regular file", filename);
    }
    size_ = static_cast<size_t>(info.st_size);
    if (size_ == 0) {
        ::close(fd);
        core::ThrowError("'{}' is empty", filename);
    }
    // MAP_POPULATE maps the whole file in one go instead of one page fault per 4 KiB. With a
    // progress callback a file above 16 MiB is populated in 4 MiB blocks instead, reported as
    // "reading" (the disk is then what a large file waits for).
    constexpr size_t kBlock = size_t(4) << 20;
    const bool report = populate && core::HasProgressCallback() && size_ > 4 * kBlock;
    const int flags = MAP_PRIVATE | (populate && !report ? MAP_POPULATE : 0);
    void* p = ::mmap(nullptr, size_, PROT_READ, flags, fd, 0);
    ::close(fd);
    if (p == MAP_FAILED) core::ThrowError("Cannot map '{}': {}", filename, std::strerror(errno));
    data_ = static_cast<const uint8_t*>(p);
    if (report) {
        const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
        for (size_t at = 0; at < size_; at += kBlock) {
            core::ReportProgress("reading", double(at) / size_);
            const size_t end = std::min(size_, at + kBlock);
            ::madvise(const_cast<uint8_t*>(data_) + at, end - at, MADV_WILLNEED);
            volatile uint8_t sink = 0;
            for (size_t q = at; q < end; q += page) sink = sink + data_[q];  // fault the pages in
        }
        core::ReportProgress("reading", 1.0);
    }
}

MappedFile::~MappedFile() {
    if (data_ != nullptr) ::munmap(const_cast<uint8_t*>(data_), size_);
}

std::vector<SplatAttribute> SplatAttributesInFileOrder(int num_rest) {
    std::vector<SplatAttribute> list = {{geometry::gs_attr::kPositions, 3},
                                        {geometry::gs_attr::kScale, 3},
                                        {geometry::gs_attr::kRot, 4},
                                        {geometry::gs_attr::kOpacity, 1},
                                        {geometry::gs_attr::kFDc, 3}};
    if (num_rest > 0) list.push_back({geometry::gs_attr::kFRest, 3 * int64_t(num_rest)});
    return list;
}

geometry::PointCloud ReadSplatAttributeBlocks(
    const uint8_t* at, int64_t n, int num_rest,
    const std::function<void(const char* name, int64_t row)>& non_finite) {
    geometry::PointCloud cloud;
    for (const SplatAttribute& a : SplatAttributesInFileOrder(num_rest)) {
        core::SizeVector shape = {n, a.width};
        if (a.name == std::string(geometry::gs_attr::kFRest)) shape = {n, num_rest, 3};
        core::Tensor values(shape, core::Dtype::Float32);
        std::memcpy(values.Data<float>(), at, 4 * n * a.width);
        at += 4 * n * a.width;
        const float* v = values.Data<float>();
        for (int64_t i = 0; i < n * a.width; ++i) {
            if (!std::isfinite(v[i])) non_finite(a.name, i / a.width);
        }
        if (a.name == std::string(geometry::gs_attr::kPositions)) {
            cloud = geometry::PointCloud(values);
        } else {
            cloud.SetPointAttr(a.name, values);
        }
    }
    return cloud;
}

void WriteFileBytes(const std::string& filename, const std::vector<uint8_t>& bytes) {
    std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(filename.c_str(), "wb"), &std::fclose);
    if (!file) core::ThrowError("Cannot open '{}' for writing: {}", filename, std::strerror(errno));
    if (std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size() ||
        std::fflush(file.get()) != 0) {
        core::ThrowError("Cannot write '{}': {}", filename, std::strerror(errno));
    }
}

namespace {

enum VertexStatus : uint8_t { kOk = 0, kNonFinite = 1, kZeroQuaternion = 2 };

float* F(core::Tensor& t) { return t.NumBytes() > 0 ? t.Data<float>() : nullptr; }

bool AllFinite(const float* v, int64_t n) {
    for (int64_t i = 0; i < n; ++i) {
        if (!std::isfinite(v[i])) return false;
    }
    return true;
}

// Names the first non-finite attribute of vertex i, for the error message.
std::string DescribeNonFinite(const SplatColumns& c, int64_t i) {
    const int nc = NumSHRestCoeffs(c.sh_degree);
    struct Column {
        const char* name;
        const core::Tensor* data;
        int64_t width;
    };
    const Column columns[] = {{"position", &c.positions, 3},
                              {"scale (exp of log-scale)", &c.scale, 3},
                              {"rot", &c.rot, 4},
                              {"opacity", &c.opacity, 1},
                              {"f_dc", &c.f_dc, 3},
                              {"f_rest", &c.f_rest, nc * 3}};
    for (const Column& col : columns) {
        if (col.data->NumBytes() == 0) continue;
        for (int64_t k = 0; k < col.width; ++k) {
            const float v = col.data->Data<float>()[i * col.width + k];
            if (!std::isfinite(v)) return fmt::format("{}[{}] = {}", col.name, k, v);
        }
    }
    return "unknown";
}

// Keeps the rows whose status is kOk, in order, in a new tensor of m rows.
core::Tensor Compact(const core::Tensor& column, int64_t m, const std::vector<uint8_t>& status) {
    core::SizeVector shape = column.GetShape();
    const int64_t width = column.NumElements() / std::max<int64_t>(1, shape[0]);
    shape[0] = m;
    core::Tensor out = core::Tensor::Empty(shape, core::Dtype::Float32);
    const float* src = column.Data<float>();
    float* dst = out.Data<float>();
    for (size_t i = 0; i < status.size(); ++i) {
        if (status[i] != kOk) continue;
        dst = std::copy_n(src + i * width, width, dst);
    }
    return out;
}

}  // namespace

geometry::PointCloud FinalizeColumns(const std::string& filename, SplatColumns& c,
                                     const ReadPointCloudOptions& options,
                                     ReadPointCloudReport& report) {
    const int64_t n = c.num_points;
    const int nc = NumSHRestCoeffs(c.sh_degree);
    std::vector<uint8_t> status(n, kOk);
    core::ParallelFor(
        n,
        [&](int64_t i) {
            bool finite = AllFinite(F(c.positions) + i * 3, 3);
            if (c.is_gaussian) {
                finite = finite && AllFinite(F(c.scale) + i * 3, 3) &&
                         AllFinite(F(c.rot) + i * 4, 4) && AllFinite(F(c.opacity) + i, 1) &&
                         AllFinite(F(c.f_dc) + i * 3, 3) &&
                         (nc == 0 || AllFinite(F(c.f_rest) + i * nc * 3, nc * 3));
            }
            if (!finite) {
                status[i] = kNonFinite;
                return;
            }
            if (!c.is_gaussian) return;
            float* q = F(c.rot) + i * 4;
            const double n2 = double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] +
                              double(q[3]) * q[3];
            if (n2 == 0.0) {
                status[i] = kZeroQuaternion;
                return;
            }
            // Already-unit quaternions (|n2 - 1| <= 2^-20, i.e. within ~4 float ulps)
            // are kept bit-exact so that write -> read round trips are exact.
            if (std::abs(n2 - 1.0) > 0x1p-20) {
                const double inv = 1.0 / std::sqrt(n2);
                for (int k = 0; k < 4; ++k) q[k] = static_cast<float>(q[k] * inv);
            }
        },
        4096);

    int64_t non_finite = 0;
    for (int64_t i = 0; i < n; ++i) {
        if (status[i] == kZeroQuaternion) {
            core::ThrowError("'{}': splat {} has a zero rotation quaternion (cannot be normalised)",
                             filename, i);
        }
        if (status[i] == kNonFinite) {
            if (!options.drop_non_finite) {
                core::ThrowError(
                    "'{}': splat {} has a non-finite value: {} (set drop_non_finite to skip "
                    "such splats)",
                    filename, i, DescribeNonFinite(c, i));
            }
            ++non_finite;
        }
    }
    const int64_t m = n - non_finite;
    if (non_finite > 0) {
        core::LogWarning("'{}': dropped {} of {} splats with NaN/Inf values", filename, non_finite,
                         n);
        c.positions = Compact(c.positions, m, status);
        if (c.is_gaussian) {
            c.scale = Compact(c.scale, m, status);
            c.rot = Compact(c.rot, m, status);
            c.opacity = Compact(c.opacity, m, status);
            c.f_dc = Compact(c.f_dc, m, status);
            c.f_rest = Compact(c.f_rest, m, status);
        }
    }
    report.num_points = m;
    report.dropped_non_finite = non_finite;

    geometry::PointCloud cloud(std::move(c.positions));
    if (c.is_gaussian) {
        cloud.SetPointAttr(geometry::gs_attr::kScale, std::move(c.scale));
        cloud.SetPointAttr(geometry::gs_attr::kRot, std::move(c.rot));
        cloud.SetPointAttr(geometry::gs_attr::kOpacity, std::move(c.opacity));
        cloud.SetPointAttr(geometry::gs_attr::kFDc, std::move(c.f_dc));
        if (nc > 0) cloud.SetPointAttr(geometry::gs_attr::kFRest, std::move(c.f_rest));
    }
    return cloud;
}

}  // namespace io
}  // namespace t
}  // namespace open3d
