// An H.264 MP4 video written frame by frame from 8-bit RGB(A) images: libx264 (Debian's
// libx264-164) encodes, t/io/Mp4Muxer.h stores. No ffmpeg program or library is involved.
// Colour: BT.709 limited range 4:2:0 (the common HD convention), flagged in the stream with the
// sRGB transfer curve, so players show the images' sRGB colours.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace open3d {
namespace t {
namespace io {

struct H264VideoOptions {
    /// x264 speed preset, "ultrafast" .. "placebo" (x264 --fullhelp lists them).
    std::string preset = "veryfast";
    /// Constant rate factor, 1 (best) .. 51 (worst); 23 is x264's and ffmpeg's default. Lossless
    /// (0) would need the High 4:4:4 profile, which few players decode.
    float crf = 23.0f;
    /// Encoder threads; 0 lets x264 choose (1.5 per core).
    int threads = 0;
};

/// Throws naming the option unless the preset is one of x264's and the rate factor is in
/// [1, 51]: tools call it before any work; the writer's constructor calls it too.
void CheckH264VideoOptions(const H264VideoOptions& options);

class H264VideoWriter {
public:
    /// Checks the arguments and starts the encoder; the file appears at `path` only when
    /// Finish succeeds (it is written to a temporary beside it until then). An odd width or
    /// height is padded by one column or row repeating the edge (4:2:0 needs even sizes).
    H264VideoWriter(const std::string& path, int width, int height, double fps,
                    const H264VideoOptions& options = {});
    /// Without Finish (an exception on the way), removes the temporary: no partial video.
    ~H264VideoWriter();
    H264VideoWriter(const H264VideoWriter&) = delete;
    H264VideoWriter& operator=(const H264VideoWriter&) = delete;

    /// Encodes one frame: width x height pixels of `channels` bytes (3: RGB, 4: RGBA with the
    /// alpha ignored), rows top to bottom, `row_bytes` apart (0: width x channels).
    void WriteFrame(const uint8_t* pixels, int channels, size_t row_bytes = 0);
    /// Encodes the frames the encoder still holds, writes the index and publishes the file.
    /// Returns the number of frames.
    size_t Finish();

    /// The size the stream codes (the even size a padded odd one becomes).
    int CodedWidth() const;
    int CodedHeight() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace io
}  // namespace t
}  // namespace open3d
