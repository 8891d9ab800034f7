// An H.264 stream stored as an MP4 file (ISO/IEC 14496-12 boxes with the avcC record of
// ISO/IEC 14496-15): one video track at a constant frame rate. The samples go into one mdat as
// they arrive, so a long video never sits in memory, and the index (moov) follows them when
// the stream ends. Every sample is its own chunk (one 64-bit offset each).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace open3d {
namespace t {
namespace io {

/// What the track's sample description says about the stream.
struct Mp4VideoTrack {
    int width = 0;  ///< coded size in pixels (even for 4:2:0)
    int height = 0;
    double fps = 0;  ///< frames per second, > 0
    std::vector<uint8_t>
        sps;  ///< the sequence parameter set NAL unit, without start code or length
    std::vector<uint8_t> pps;  ///< the picture parameter set NAL unit, likewise
};

/// Ticks per second of the track's clock: 90 kHz, the MPEG convention, which holds the common
/// rates' frame durations exactly (30 fps: 3,000 ticks; 29.97: 3,003; 24: 3,750).
constexpr uint32_t kMp4VideoTimescale = 90000;

class Mp4Muxer {
public:
    /// Creates `path` (replacing it) and writes the file type and the sample data's header.
    /// Throws naming the path when it cannot be written or the track is not valid.
    Mp4Muxer(const std::string& path, const Mp4VideoTrack& track);
    /// Closes the file; without Finish it has no index and plays nowhere (callers write to a
    /// temporary: t/io/OutputFiles.h).
    ~Mp4Muxer();
    Mp4Muxer(const Mp4Muxer&) = delete;
    Mp4Muxer& operator=(const Mp4Muxer&) = delete;

    /// Appends one frame: its NAL units, each preceded by its size as 4 big-endian bytes (what
    /// an encoder writes without Annex B start codes). `sync`: an IDR frame, where playback
    /// may start.
    void AddSample(const uint8_t* data, size_t size, bool sync);
    /// Writes the sample data's size and the index, and closes the file. Throws on a write
    /// error or when no sample was added.
    void Finish();

    size_t SampleCount() const { return sizes_.size(); }

private:
    void Write(const void* data, size_t size);

    std::string path_;
    Mp4VideoTrack track_;
    FILE* file_ = nullptr;
    uint64_t mdat_start_ = 0;  ///< file offset of the mdat box
    uint64_t offset_ = 0;      ///< file offset of the next sample
    std::vector<uint32_t> sizes_;
    std::vector<uint64_t> offsets_;
    std::vector<uint32_t> sync_samples_;  ///< 1-based sample numbers of the IDR frames
};

}  // namespace io
}  // namespace t
}  // namespace open3d
