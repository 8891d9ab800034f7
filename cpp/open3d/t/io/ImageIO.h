// Image files: PNG (8-bit grey/GA/RGB/RGBA, 16-bit grey) through libpng, and NumPy .npy
// float/uint8 dumps ([rows, cols, channels], little endian, C order) for exact values.
// Failures throw core::Open3DError naming the file.
#pragma once

#include <string>

#include "open3d/t/geometry/Image.h"

namespace open3d {
namespace t {
namespace io {

/// Writes a UInt8 image with 1 (grey), 2 (grey + alpha), 3 (RGB) or 4 (RGBA) channels.
void WritePNG(const std::string& filename, const geometry::Image& image);

/// Writes a 1-channel Float32 image as a 16-bit grey PNG: round(clamp(v * scale, 0, 65535)).
/// With scale = 1000, a value in metres is stored in millimetres (up to 65.535 m).
/// Returns how many pixels were above the range and saturated to 65535 (callers warn).
int64_t WritePNG16(const std::string& filename, const geometry::Image& image, double scale);

/// Reads a PNG. 8-bit files (palette expanded to RGB/RGBA, low bit depths to 8) come back
/// as UInt8 with the file's channel count; 16-bit files as Float32 holding the raw
/// values 0..65535.
geometry::Image ReadPNG(const std::string& filename);

/// Writes a Float32, UInt8 or UInt16 image as a NumPy .npy array of shape
/// [rows, cols, channels] (format version 1.0, '<f4', '|u1' or '<u2'); numpy.load reads it.
void WriteNpy(const std::string& filename, const geometry::Image& image);
/// Reads what WriteNpy writes ('<f4', '|u1' or '<u2', C order, rank 3 with 1..4 channels).
geometry::Image ReadNpy(const std::string& filename);

/// Writes by extension: .png (UInt8 images; Float32 images are converted with
/// Image::ToUInt8(255)) or .npy.
void WriteImage(const std::string& filename, const geometry::Image& image);

}  // namespace io
}  // namespace t
}  // namespace open3d
