// The original 3DGS rasterizer's output around the worst pixels of three views
// (../shared/data/parity/: 128 x 128 float32 RGB crops of its 800 x 800 renders, black
// background, README there), and how a render of ours is compared with them. Shared by the
// CPU reference's and the Vulkan backend's parity tests.
#pragma once

#include <string>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/t/io/ImageIO.h"

namespace open3d {
namespace tests {

struct ParityCrop {
    const char* name;     // crop file stem under parity/
    const char* scene;    // scene file, relative to the data folder
    const char* cameras;  // its cameras.json
    int view;
    int x0, y0;  // crop origin in the 800 x 800 image (column, row): parity/crops.json
    // The bar, 100 dB (the issue's), but where one pixel's threshold decision is measured to
    // differ: biker view 19 (pixel 506, 104) blends splat 107959 in the stored crop, whose
    // alpha there is 1/255 - 2.2e-7 in our float32 evaluation (its power is -3.09110, a sum of
    // terms of about +-48 that cancel). The original itself, rendered by scripts/parity from
    // our inputs, skips it too: its fresh crop differs from the stored one at that pixel alone
    // (99.78 dB, 0.00131), so the inputs the stored crops were made from rounded differently
    // there, and against the fresh render the CPU reference scores 119.6 dB on the whole view
    // (Vulkan 102.3 dB; docs/accuracy.md). The stored crop scores 99.75 dB (CPU reference).
    double min_psnr_db;
    // The Vulkan backend's bar: its composite decides the thresholds on its own float32
    // centre and conic, and flips two more pixels of the stored biker view 19 crop (98.66 dB
    // on lavapipe, max error 0.0013, the same pixel worst).
    double vulkan_min_psnr_db;
};

// crops.json's origins; each crop is 128 x 128.
inline constexpr ParityCrop kParityCrops[] = {
    {"playbot_31k_view9", "playbot/playbot_31k.ply", "playbot/cameras.json", 9, 232, 617, 100.0,
     100.0},
    {"biker_view19", "biker/biker_152k.ply", "biker/cameras.json", 19, 441, 49, 99.5, 98.5},
    {"biker_view14", "biker/biker_152k.ply", "biker/cameras.json", 14, 415, 640, 100.0, 100.0},
};
inline constexpr int kParityImageSize = 800;
inline constexpr int kParityCropSize = 128;

inline void PrintTo(const ParityCrop& c, std::ostream* os) { *os << c.name; }

inline std::string ParityCropPath(const ParityCrop& c) {
    return DataPath(std::string("parity/") + c.name + "_ref_crop.npy");
}

/// The view exactly as the crops were rendered: the scene's camera at 800 x 800 (fx scaled
/// by 800 / height, principal point at the image centre).
inline camera::PinholeCamera ParityCamera(const ParityCrop& c) {
    return camera::ReadCamerasJson(DataPath(c.cameras))
        .at(c.view)
        .camera.Resized(kParityImageSize, kParityImageSize);
}

/// The crop's window of an [800, 800, >= 3] float render, as RGB [128, 128, 3].
inline t::geometry::Image CropRGB(const t::geometry::Image& render, const ParityCrop& c) {
    const int channels = static_cast<int>(render.GetChannels());
    t::geometry::Image crop(kParityCropSize, kParityCropSize, 3, core::Dtype::Float32);
    const float* src = render.Data<float>();
    float* dst = crop.Data<float>();
    for (int y = 0; y < kParityCropSize; ++y) {
        for (int x = 0; x < kParityCropSize; ++x) {
            const int64_t s = (int64_t(c.y0 + y) * render.GetCols() + (c.x0 + x)) * channels;
            for (int ch = 0; ch < 3; ++ch) dst[(y * kParityCropSize + x) * 3 + ch] = src[s + ch];
        }
    }
    return crop;
}

/// PSNR (peak 1), max abs error and share above 1/255 of our crop against the original's.
inline t::geometry::ImageErrorMetrics CompareWithParityCrop(const t::geometry::Image& render,
                                                            const ParityCrop& c) {
    const t::geometry::Image ref = t::io::ReadNpy(ParityCropPath(c));
    return t::geometry::ComputeImageErrorMetrics(CropRGB(render, c), ref, 1.0, 1.0 / 255.0);
}

}  // namespace tests
}  // namespace open3d
