#include "open3d/t/io/H264VideoWriter.h"

#include <x264.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/io/Mp4Muxer.h"
#include "open3d/t/io/OutputFiles.h"

namespace open3d {
namespace t {
namespace io {

namespace {

// BT.709 luma weights; limited range puts luma in [16, 235] and chroma in [16, 240].
constexpr float kKr = 0.2126f, kKb = 0.0722f, kKg = 1.0f - kKr - kKb;
constexpr float kLumaScale = 219.0f / 255.0f, kChromaScale = 224.0f / 255.0f;

uint8_t ToByte(float v) { return uint8_t(std::clamp(std::lround(v), 0L, 255L)); }

// The NAL unit of a payload x264 wrote without start codes: its 4-byte size comes first.
std::vector<uint8_t> NalBody(const x264_nal_t& nal) {
    return std::vector<uint8_t>(nal.p_payload + 4, nal.p_payload + nal.i_payload);
}

}  // namespace

void CheckH264VideoOptions(const H264VideoOptions& options) {
    bool known = false;
    std::string names;
    for (int k = 0; x264_preset_names[k] != nullptr; ++k) {
        known = known || options.preset == x264_preset_names[k];
        names += std::string(k > 0 ? ", " : "") + x264_preset_names[k];
    }
    if (!known) core::ThrowError("--preset '{}' is not an x264 preset ({})", options.preset, names);
    if (!(options.crf >= 1.0f && options.crf <= 51.0f))
        core::ThrowError("--crf {}: the constant rate factor is 1 (best) to 51 (worst)",
                         options.crf);
}

struct H264VideoWriter::State {
    std::string path;
    int width = 0, height = 0;              // the frames'
    int coded_width = 0, coded_height = 0;  // even
    OutputFileSet files;  // before the muxer: the muxer's file closes before the set removes it
    std::unique_ptr<Mp4Muxer> muxer;
    x264_t* encoder = nullptr;
    x264_picture_t picture;
    bool picture_allocated = false;
    int64_t frames_in = 0;
    bool finished = false;

    ~State() {
        if (encoder != nullptr) x264_encoder_close(encoder);
        if (picture_allocated) x264_picture_clean(&picture);
    }

    // Stores what one encoder call returned (the NAL units of one frame, contiguous).
    void Store(x264_nal_t* nals, int nal_count, int bytes, const x264_picture_t& out) {
        if (bytes < 0) core::ThrowError("'{}': the H.264 encoder failed", path);
        if (bytes == 0 || nal_count == 0) return;
        muxer->AddSample(nals[0].p_payload, size_t(bytes), out.b_keyframe != 0);
    }
};

H264VideoWriter::H264VideoWriter(const std::string& path, int width, int height, double fps,
                                 const H264VideoOptions& options)
    : state_(std::make_unique<State>()) {
    State& s = *state_;
    s.path = path;
    if (width <= 0 || height <= 0 || width > 16384 || height > 16384)
        core::ThrowError("'{}': a video of {}x{} pixels cannot be encoded (1 to 16384 each)", path,
                         width, height);
    if (!(fps > 0.0) || !std::isfinite(fps) || fps > 1000.0)
        core::ThrowError("'{}': {} frames per second cannot be encoded (above 0, at most 1000)",
                         path, fps);
    CheckH264VideoOptions(options);
    CheckOutputPath("the video", path);  // a missing folder is named before any encoding
    s.width = width;
    s.height = height;
    s.coded_width = width + (width & 1);
    s.coded_height = height + (height & 1);

    x264_param_t param;
    if (x264_param_default_preset(&param, options.preset.c_str(), nullptr) < 0)
        core::ThrowError("'{}': x264 refused the preset '{}'", path, options.preset);
    param.i_threads = options.threads > 0 ? options.threads : X264_THREADS_AUTO;
    param.i_log_level = X264_LOG_WARNING;
    param.i_csp = X264_CSP_I420;
    param.i_width = s.coded_width;
    param.i_height = s.coded_height;
    param.b_vfr_input = 0;
    // fps as a fraction with a millisecond-rate numerator: 30 -> 30000/1000, 29.97 -> 29970/1000.
    param.i_fps_num = uint32_t(std::lround(fps * 1000.0));
    param.i_fps_den = 1000;
    param.i_timebase_num = param.i_fps_den;
    param.i_timebase_den = param.i_fps_num;
    // No B-frames: decoding order is display order, so the MP4 needs no composition offsets.
    param.i_bframe = 0;
    param.b_repeat_headers = 0;  // the parameter sets live in the MP4's avcC record
    param.b_annexb = 0;          // sizes, not start codes, before each NAL unit
    param.vui.b_fullrange = 0;
    param.vui.i_colorprim = 1;  // BT.709 primaries (those of sRGB)
    param.vui.i_transfer = 13;  // IEC 61966-2-1, the sRGB curve the images are in
    param.vui.i_colmatrix = 1;  // BT.709 matrix
    param.rc.i_rc_method = X264_RC_CRF;
    param.rc.f_rf_constant = options.crf;
    if (x264_param_apply_profile(&param, "high") < 0)
        core::ThrowError("'{}': x264 refused the H.264 profile", path);
    s.encoder = x264_encoder_open(&param);
    if (s.encoder == nullptr)
        core::ThrowError("'{}': x264 could not start an encoder for {}x{} at {} fps", path,
                         s.coded_width, s.coded_height, fps);
    if (x264_picture_alloc(&s.picture, X264_CSP_I420, s.coded_width, s.coded_height) < 0)
        core::ThrowError("'{}': out of memory for a {}x{} frame", path, s.coded_width,
                         s.coded_height);
    s.picture_allocated = true;

    x264_nal_t* nals = nullptr;
    int nal_count = 0;
    if (x264_encoder_headers(s.encoder, &nals, &nal_count) < 0)
        core::ThrowError("'{}': x264 wrote no stream headers", path);
    Mp4VideoTrack track;
    track.width = s.coded_width;
    track.height = s.coded_height;
    track.fps = fps;
    for (int k = 0; k < nal_count; ++k) {
        if (nals[k].i_type == NAL_SPS) track.sps = NalBody(nals[k]);
        if (nals[k].i_type == NAL_PPS) track.pps = NalBody(nals[k]);
    }
    s.muxer = std::make_unique<Mp4Muxer>(s.files.Add(path), track);
}

H264VideoWriter::~H264VideoWriter() = default;

int H264VideoWriter::CodedWidth() const { return state_->coded_width; }
int H264VideoWriter::CodedHeight() const { return state_->coded_height; }

void H264VideoWriter::WriteFrame(const uint8_t* pixels, int channels, size_t row_bytes) {
    State& s = *state_;
    if (s.finished) core::ThrowError("'{}': the video is already finished", s.path);
    if (channels != 3 && channels != 4)
        core::ThrowError("'{}': frames have 3 (RGB) or 4 (RGBA) channels, not {}", s.path,
                         channels);
    if (row_bytes == 0) row_bytes = size_t(s.width) * channels;
    const int w = s.width, h = s.height;
    x264_image_t& img = s.picture.img;
    // Pixel (x, y) of the frame, the padding repeating the last column and row.
    auto rgb = [&](int x, int y) {
        const uint8_t* p =
            pixels + size_t(std::min(y, h - 1)) * row_bytes + size_t(std::min(x, w - 1)) * channels;
        return p;
    };
    // One pair of coded rows per task: its luma rows and the chroma row of their 2x2 blocks
    // (chroma from the block's mean colour; the matrix is linear, so that is the mean chroma).
    core::ParallelFor(
        s.coded_height / 2,
        [&](int64_t pair) {
            const int y0 = int(pair) * 2;
            uint8_t* cb = img.plane[1] + size_t(pair) * img.i_stride[1];
            uint8_t* cr = img.plane[2] + size_t(pair) * img.i_stride[2];
            for (int x0 = 0; x0 < s.coded_width; x0 += 2) {
                float sum[3] = {0, 0, 0};
                for (int dy = 0; dy < 2; ++dy) {
                    uint8_t* luma = img.plane[0] + size_t(y0 + dy) * img.i_stride[0];
                    for (int dx = 0; dx < 2; ++dx) {
                        const uint8_t* p = rgb(x0 + dx, y0 + dy);
                        const float r = p[0], g = p[1], b = p[2];
                        luma[x0 + dx] = ToByte(16.0f + kLumaScale * (kKr * r + kKg * g + kKb * b));
                        sum[0] += r;
                        sum[1] += g;
                        sum[2] += b;
                    }
                }
                const float r = sum[0] / 4, g = sum[1] / 4, b = sum[2] / 4;
                const float y = kKr * r + kKg * g + kKb * b;
                cb[x0 / 2] = ToByte(128.0f + kChromaScale * (b - y) / (2.0f * (1.0f - kKb)));
                cr[x0 / 2] = ToByte(128.0f + kChromaScale * (r - y) / (2.0f * (1.0f - kKr)));
            }
        },
        16);
    s.picture.i_pts = s.frames_in++;
    x264_picture_t out;
    x264_nal_t* nals = nullptr;
    int nal_count = 0;
    const int bytes = x264_encoder_encode(s.encoder, &nals, &nal_count, &s.picture, &out);
    s.Store(nals, nal_count, bytes, out);
}

size_t H264VideoWriter::Finish() {
    State& s = *state_;
    if (s.finished) core::ThrowError("'{}': the video is already finished", s.path);
    while (x264_encoder_delayed_frames(s.encoder) > 0) {
        x264_picture_t out;
        x264_nal_t* nals = nullptr;
        int nal_count = 0;
        const int bytes = x264_encoder_encode(s.encoder, &nals, &nal_count, nullptr, &out);
        s.Store(nals, nal_count, bytes, out);
    }
    if (s.muxer->SampleCount() != size_t(s.frames_in))
        core::ThrowError("'{}': {} frames went in, the encoder returned {}", s.path, s.frames_in,
                         s.muxer->SampleCount());
    s.muxer->Finish();
    s.files.Commit();
    s.finished = true;
    return s.muxer->SampleCount();
}

}  // namespace io
}  // namespace t
}  // namespace open3d
