// The compressed PLY writer (layout and choices: CompressedPlyLayout.h).
#include "open3d/t/io/CompressedPlyLayout.h"

namespace open3d {
namespace t {
namespace io {
namespace {

using namespace compressed_ply;

// ---------------------------------------------------------------------------------------
// Writer.

uint32_t PackUnorm(double value, int bits) {  // compressed-chunk.ts packUnorm
    const double top = (1u << bits) - 1;
    return static_cast<uint32_t>(std::clamp(std::floor(value * top + 0.5), 0.0, top));
}

double Normalise(double x, double lo, double hi) {
    if (x <= lo) return 0.0;
    if (x >= hi) return 1.0;
    return (x - lo) / (hi - lo);
}

// The code nearest to x in [lo, hi]; a neighbour instead when only it decodes to `target`.
template <typename Decode>
uint32_t Quantise(double x, double lo, double hi, int bits, float target, Decode decode) {
    const uint32_t code = PackUnorm(Normalise(x, lo, hi), bits);
    if (decode(code) == target) return code;
    const uint32_t top = (1u << bits) - 1;
    if (code > 0 && decode(code - 1) == target) return code - 1;
    if (code < top && decode(code + 1) == target) return code + 1;
    return code;
}

// compressed-chunk.ts packRot: normalise, largest |component| positive, three 10-bit values.
uint32_t PackRotationReference(const float rot[4]) {
    double q[4];
    const double length = std::sqrt(double(rot[0]) * rot[0] + double(rot[1]) * rot[1] +
                                    double(rot[2]) * rot[2] + double(rot[3]) * rot[3]);
    const double inv = 1.0 / length;
    for (int k = 0; k < 4; ++k) q[k] = rot[k] * inv;
    int largest = 0;
    for (int k = 1; k < 4; ++k) {
        if (std::abs(q[k]) > std::abs(q[largest])) largest = k;
    }
    if (q[largest] < 0) {
        for (double& v : q) v = -v;
    }
    uint32_t word = static_cast<uint32_t>(largest);
    for (int k = 0; k < 4; ++k) {
        if (k != largest) word = (word << 10) | PackUnorm(q[k] * kRotEncodeNorm + 0.5, 10);
    }
    return word;
}

bool SameRotation(uint32_t word, const float rot[4]) {
    float decoded[4];
    DecodeRotation(word, decoded);
    return decoded[0] == rot[0] && decoded[1] == rot[1] && decoded[2] == rot[2] &&
           decoded[3] == rot[3];
}

// The reference code, or one that decodes to exactly `rot` when such a code exists (a near
// tie for the largest component can make the reference choose another index than the one
// the value was decoded from).
uint32_t PackRotation(const float rot[4]) {
    const uint32_t reference = PackRotationReference(rot);
    if (SameRotation(reference, rot)) return reference;
    float max_abs = 0.0f;
    for (int k = 0; k < 4; ++k) max_abs = std::max(max_abs, std::abs(rot[k]));
    for (uint32_t largest = 0; largest < 4; ++largest) {
        if (rot[largest] < 0.0f || rot[largest] < max_abs - 0.01f) continue;
        uint32_t word = largest;
        for (uint32_t k = 0; k < 4; ++k) {
            if (k != largest) word = (word << 10) | PackUnorm(rot[k] * kRotEncodeNorm + 0.5, 10);
        }
        if (SameRotation(word, rot)) return word;
    }
    return reference;
}

uint8_t QuantiseSH(float v) {  // write-compressed-ply.ts
    const double unit = double(v) / 8.0 + 0.5;
    return static_cast<uint8_t>(std::clamp(std::trunc(unit * 256.0), 0.0, 255.0));
}

// https://fgiesen.wordpress.com/2009/12/13/decoding-morton-codes/ (as morton-order.ts).
uint32_t Part1By2(uint32_t x) {
    x &= 0x000003ff;
    x = (x ^ (x << 16)) & 0xff0000ff;
    x = (x ^ (x << 8)) & 0x0300f00f;
    x = (x ^ (x << 4)) & 0x030c30c3;
    x = (x ^ (x << 2)) & 0x09249249;
    return x;
}

// morton-order.ts sortMortonOrder on order[begin, end).
void SortMorton(const float* positions, std::vector<uint32_t>& order, size_t begin, size_t end) {
    if (begin >= end) return;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = begin; i < end; ++i) {
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], double(positions[size_t(order[i]) * 3 + a]));
            hi[a] = std::max(hi[a], double(positions[size_t(order[i]) * 3 + a]));
        }
    }
    double mul[3];
    bool all_zero = true;
    for (int a = 0; a < 3; ++a) {
        const double length = hi[a] - lo[a];
        if (!std::isfinite(length)) return;
        all_zero = all_zero && length == 0.0;
        mul[a] = length == 0.0 ? 0.0 : 1024.0 / length;
    }
    if (all_zero) return;
    std::vector<std::pair<uint32_t, uint32_t>> keyed(end - begin);  // (code, splat)
    for (size_t i = begin; i < end; ++i) {
        uint32_t cell[3];
        for (int a = 0; a < 3; ++a) {
            const double v = (double(positions[size_t(order[i]) * 3 + a]) - lo[a]) * mul[a];
            cell[a] = static_cast<uint32_t>(std::min(1023.0, v));
        }
        keyed[i - begin] = {(Part1By2(cell[2]) << 2) + (Part1By2(cell[1]) << 1) + Part1By2(cell[0]),
                            order[i]};
    }
    std::stable_sort(keyed.begin(), keyed.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (size_t i = begin; i < end; ++i) order[i] = keyed[i - begin].second;
    for (size_t start = 0; start < keyed.size();) {
        size_t stop = start + 1;
        while (stop < keyed.size() && keyed[stop].first == keyed[start].first) ++stop;
        if (stop - start > static_cast<size_t>(kChunkSplats)) {
            SortMorton(positions, order, begin + start, begin + stop);
        }
        start = stop;
    }
}

// Summed position quanta of the chunks an order makes (smaller is finer quantisation).
double ChunkCost(const float* positions, const std::vector<uint32_t>& order) {
    double cost = 0.0;
    for (size_t start = 0; start < order.size(); start += kChunkSplats) {
        const size_t stop = std::min(order.size(), start + kChunkSplats);
        for (int a = 0; a < 3; ++a) {
            double lo = INFINITY, hi = -INFINITY;
            for (size_t i = start; i < stop; ++i) {
                lo = std::min(lo, double(positions[size_t(order[i]) * 3 + a]));
                hi = std::max(hi, double(positions[size_t(order[i]) * 3 + a]));
            }
            cost += (hi - lo) / ((1 << kBits111011[a]) - 1);
        }
    }
    return cost;
}

void CheckWritable(const std::string& filename, const geometry::GaussianSplatArrays& a) {
    const int nc = a.num_rest;
    for (int64_t i = 0; i < a.num_points; ++i) {
        auto fail = [&](const char* what, double value) {
            core::ThrowError(
                "Cannot write '{}': splat {} has {} {}, which compressed PLY cannot store",
                filename, i, what, value);
        };
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(a.positions[i * 3 + c]))
                fail("a non-finite position", a.positions[i * 3 + c]);
            if (!(a.scale[i * 3 + c] >= 0.0f) || std::isinf(a.scale[i * 3 + c]))
                fail("a negative or non-finite scale", a.scale[i * 3 + c]);
            if (!std::isfinite(a.f_dc[i * 3 + c])) fail("a non-finite f_dc", a.f_dc[i * 3 + c]);
        }
        if (std::isnan(a.opacity[i])) fail("opacity", a.opacity[i]);
        double n2 = 0.0;
        for (int c = 0; c < 4; ++c) {
            const float q = a.rot[i * 4 + c];
            if (!std::isfinite(q)) fail("a non-finite rotation component", q);
            n2 += double(q) * q;
        }
        if (n2 == 0.0) fail("a zero rotation quaternion, norm", 0.0);
        for (int k = 0; k < nc * 3; ++k) {
            if (std::isnan(a.f_rest[i * nc * 3 + k])) fail("f_rest", a.f_rest[i * nc * 3 + k]);
        }
    }
}

// The format keeps SH in 8 bits over [-4, 4]: steps of 1/32, no exact zero (a zero reads back
// as +1/64) and coefficients beyond +-4 clamped. Says what that costs this cloud, since the
// rest of the format is exact to far finer steps.
void WarnAboutShPrecision(const std::string& filename, const geometry::GaussianSplatArrays& a) {
    const int64_t count = a.num_points * a.num_rest * 3;
    double worst = 0.0;
    int64_t clamped = 0;
    for (int64_t k = 0; k < count; ++k) {
        const float v = a.f_rest[k];
        worst = std::max(worst, std::abs(double(DecodeSH(QuantiseSH(v))) - v));
        clamped += std::abs(v) > 4.0f;
    }
    core::LogWarning(
        "'{}': compressed PLY keeps SH (f_rest) in 8 bits over [-4, 4] (steps of 1/32, zero "
        "reads back as 1/64): errors up to {:.4f} in this cloud, {} of {} coefficients clamped "
        "at +-4 (docs/formats.md gives the render error); .ply or .sog keep more",
        filename, worst, clamped, count);
}

}  // namespace

void WriteCompressedPly(const std::string& filename, const geometry::PointCloud& cloud) {
    if (!cloud.IsGaussianSplat()) {
        core::ThrowError(
            "Cannot write '{}': compressed PLY needs a Gaussian splat cloud (scale, rot, "
            "opacity, f_dc)",
            filename);
    }
    const geometry::GaussianSplatArrays a = cloud.GetGaussianSplatArrays();
    CheckWritable(filename, a);
    const int64_t n = a.num_points;
    if (n > int64_t(UINT32_MAX)) {
        core::ThrowError("Cannot write '{}': {} splats; compressed PLY holds at most 2^32 - 1",
                         filename, n);
    }
    const int nc = a.num_rest;
    const int64_t num_chunks = (n + kChunkSplats - 1) / kChunkSplats;
    if (nc > 0) WarnAboutShPrecision(filename, a);

    // Splat order (see the top of the file).
    std::vector<uint32_t> input_order(n), order(n);
    std::iota(input_order.begin(), input_order.end(), 0u);
    order = input_order;
    SortMorton(a.positions, order, 0, order.size());
    const double input_cost = ChunkCost(a.positions, input_order);
    const double morton_cost = ChunkCost(a.positions, order);
    if (input_cost <= kKeepInputOrderRatio * morton_cost) {
        order.swap(input_order);
        core::LogDebug("'{}': input order kept (chunk cost {} vs Morton order {})", filename,
                       input_cost, morton_cost);
    }

    std::vector<float> log_scales(n * 3);
    core::ParallelFor(
        n * 3, [&](int64_t k) { log_scales[k] = EncodeLogScale(a.scale[k]); }, 8192);

    std::vector<float> chunk_data(num_chunks * kChunkFloats);
    std::vector<uint32_t> vertex_data(n * 4);
    std::vector<uint8_t> sh_data(n * nc * 3);
    core::ParallelFor(
        num_chunks,
        [&](int64_t c) {
            const int64_t begin = c * kChunkSplats, end = std::min(n, begin + kChunkSplats);
            float* b = chunk_data.data() + c * kChunkFloats;
            for (int f = 0; f < 3; ++f) {
                float lo = INFINITY, hi = -INFINITY, slo = INFINITY, shi = -INFINITY;
                double clo = INFINITY, chi = -INFINITY;
                for (int64_t j = begin; j < end; ++j) {
                    const int64_t i = order[j];
                    lo = std::min(lo, a.positions[i * 3 + f]);
                    hi = std::max(hi, a.positions[i * 3 + f]);
                    slo = std::min(slo, log_scales[i * 3 + f]);
                    shi = std::max(shi, log_scales[i * 3 + f]);
                    const double colour = double(a.f_dc[i * 3 + f]) * kSH_C0 + 0.5;
                    clo = std::min(clo, colour);
                    chi = std::max(chi, colour);
                }
                b[f] = lo;
                b[3 + f] = hi;
                b[6 + f] = std::clamp(slo, float(-kLogScaleClamp), float(kLogScaleClamp));
                b[9 + f] = std::clamp(shi, float(-kLogScaleClamp), float(kLogScaleClamp));
                b[12 + f] = static_cast<float>(clo);
                b[15 + f] = static_cast<float>(chi);
            }
            for (int64_t j = begin; j < end; ++j) {
                const int64_t i = order[j];
                uint32_t position = 0, scale = 0, colour = 0;
                for (int f = 0; f < 3; ++f) {
                    const int shift = kShift111011[f], bits = kBits111011[f];
                    const float lo = b[f], hi = b[3 + f], slo = b[6 + f], shi = b[9 + f];
                    const float clo = b[12 + f], chi = b[15 + f];
                    position |=
                        Quantise(a.positions[i * 3 + f], lo, hi, bits, a.positions[i * 3 + f],
                                 [&](uint32_t q) { return DecodeLinear(lo, hi, q, bits); })
                        << shift;
                    scale |= Quantise(log_scales[i * 3 + f], slo, shi, bits, a.scale[i * 3 + f],
                                      [&](uint32_t q) { return DecodeScale(slo, shi, q, bits); })
                             << shift;
                    colour |= Quantise(double(a.f_dc[i * 3 + f]) * kSH_C0 + 0.5, clo, chi, 8,
                                       a.f_dc[i * 3 + f],
                                       [&](uint32_t q) { return DecodeColour(true, clo, chi, q); })
                              << (24 - 8 * f);
                }
                const double alpha = 1.0 / (1.0 + std::exp(-double(a.opacity[i])));
                colour |= Quantise(alpha, 0.0, 1.0, 8, a.opacity[i], DecodeOpacity);
                uint32_t* out = vertex_data.data() + j * 4;
                out[0] = position;
                out[1] = PackRotation(a.rot + i * 4);
                out[2] = scale;
                out[3] = colour;
                // sh: file order f_rest_[ch * Nc + k]; ours [Nc, 3].
                for (int ch = 0; ch < 3; ++ch) {
                    for (int k = 0; k < nc; ++k) {
                        sh_data[(j * 3 + ch) * nc + k] =
                            QuantiseSH(a.f_rest[(i * nc + k) * 3 + ch]);
                    }
                }
            }
        },
        1);

    std::string header =
        "ply\nformat binary_little_endian 1.0\ncomment Generated by Open3D (PlayCanvas "
        "compressed PLY)\n";
    header += fmt::format("element chunk {}\n", num_chunks);
    for (const char* name : kChunkNames) header += fmt::format("property float {}\n", name);
    header += fmt::format("element vertex {}\n", n);
    for (const char* name : kVertexNames) header += fmt::format("property uint {}\n", name);
    if (nc > 0) {
        header += fmt::format("element sh {}\n", n);
        for (int k = 0; k < nc * 3; ++k) header += fmt::format("property uchar f_rest_{}\n", k);
    }
    header += "end_header\n";

    std::vector<uint8_t> bytes(header.begin(), header.end());
    auto append = [&](const void* data, size_t count) {
        const auto* p = static_cast<const uint8_t*>(data);
        bytes.insert(bytes.end(), p, p + count);
    };
    append(chunk_data.data(), chunk_data.size() * sizeof(float));
    append(vertex_data.data(), vertex_data.size() * sizeof(uint32_t));
    append(sh_data.data(), sh_data.size());
    WriteFileBytes(filename, bytes);
}

}  // namespace io
}  // namespace t
}  // namespace open3d
