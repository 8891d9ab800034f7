#include "open3d/t/io/Mp4Muxer.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace io {

namespace {

// Big-endian box bytes. Begin/End nest: End writes the size of the box Begin opened.
class BoxWriter {
public:
    void U8(uint32_t v) { bytes_.push_back(uint8_t(v)); }
    void U16(uint32_t v) {
        U8(v >> 8);
        U8(v);
    }
    void U32(uint32_t v) {
        U16(v >> 16);
        U16(v & 0xFFFFu);
    }
    void U64(uint64_t v) {
        U32(uint32_t(v >> 32));
        U32(uint32_t(v));
    }
    void Zeros(size_t n) { bytes_.insert(bytes_.end(), n, 0); }
    void Bytes(const std::vector<uint8_t>& b) { bytes_.insert(bytes_.end(), b.begin(), b.end()); }
    void Tag(const char* fourcc) { bytes_.insert(bytes_.end(), fourcc, fourcc + 4); }
    void Begin(const char* type) {
        open_.push_back(bytes_.size());
        U32(0);
        Tag(type);
    }
    // A "full box": version and 24 bits of flags after the type.
    void BeginFull(const char* type, uint32_t version, uint32_t flags) {
        Begin(type);
        U32((version << 24) | flags);
    }
    void End() {
        const size_t start = open_.back();
        open_.pop_back();
        const uint32_t size = uint32_t(bytes_.size() - start);
        for (int k = 0; k < 4; ++k) bytes_[start + k] = uint8_t(size >> (24 - 8 * k));
    }
    // The unity transformation matrix of the movie and track headers (16.16 and 2.30 fixed).
    void UnityMatrix() {
        const uint32_t m[9] = {0x00010000, 0, 0, 0, 0x00010000, 0, 0, 0, 0x40000000};
        for (uint32_t v : m) U32(v);
    }
    const std::vector<uint8_t>& bytes() const { return bytes_; }

private:
    std::vector<uint8_t> bytes_;
    std::vector<size_t> open_;
};

// The avcC record: profile and level copied from the SPS (its bytes 1-3), NAL sizes of 4 bytes.
void WriteAvcConfiguration(BoxWriter& w, const Mp4VideoTrack& track) {
    const std::vector<uint8_t>& sps = track.sps;
    w.Begin("avcC");
    w.U8(1);         // configurationVersion
    w.U8(sps[1]);    // AVCProfileIndication
    w.U8(sps[2]);    // profile_compatibility
    w.U8(sps[3]);    // AVCLevelIndication
    w.U8(0xFC | 3);  // lengthSizeMinusOne: 4-byte sizes
    w.U8(0xE0 | 1);  // one SPS
    w.U16(uint32_t(sps.size()));
    w.Bytes(sps);
    w.U8(1);  // one PPS
    w.U16(uint32_t(track.pps.size()));
    w.Bytes(track.pps);
    // High profiles (100 and up) add the chroma format and bit depths: 4:2:0, 8 bits.
    if (sps[1] >= 100) {
        w.U8(0xFC | 1);
        w.U8(0xF8 | 0);
        w.U8(0xF8 | 0);
        w.U8(0);  // no SPS extensions
    }
    w.End();
}

}  // namespace

Mp4Muxer::Mp4Muxer(const std::string& path, const Mp4VideoTrack& track)
    : path_(path), track_(track) {
    if (track.width <= 0 || track.height <= 0 || track.width > 0xFFFF || track.height > 0xFFFF)
        core::ThrowError("'{}': an MP4 video of {}x{} pixels cannot be written", path, track.width,
                         track.height);
    if (!(track.fps > 0.0) || !std::isfinite(track.fps) || track.fps > kMp4VideoTimescale)
        core::ThrowError("'{}': {} frames per second cannot be written", path, track.fps);
    if (track.sps.size() < 4 || track.pps.empty())
        core::ThrowError("'{}': the H.264 stream has no sequence or picture parameter set", path);
    file_ = std::fopen(path.c_str(), "wb");
    if (file_ == nullptr) core::ThrowError("cannot write '{}': {}", path, std::strerror(errno));
    BoxWriter head;
    head.Begin("ftyp");
    head.Tag("isom");
    head.U32(0x200);
    for (const char* brand : {"isom", "iso2", "avc1", "mp41"}) head.Tag(brand);
    head.End();
    mdat_start_ = head.bytes().size();
    // mdat with a 64-bit size (size field 1), patched by Finish: a video may pass 4 GiB.
    head.U32(1);
    head.Tag("mdat");
    head.U64(0);
    Write(head.bytes().data(), head.bytes().size());
    offset_ = head.bytes().size();
}

Mp4Muxer::~Mp4Muxer() {
    if (file_ != nullptr) std::fclose(file_);
}

void Mp4Muxer::Write(const void* data, size_t size) {
    if (std::fwrite(data, 1, size, file_) != size)
        core::ThrowError("cannot write '{}': {}", path_, std::strerror(errno));
}

void Mp4Muxer::AddSample(const uint8_t* data, size_t size, bool sync) {
    if (file_ == nullptr) core::ThrowError("'{}': the video is already finished", path_);
    if (size == 0 || size > 0xFFFFFFFFu)
        core::ThrowError("'{}': a frame of {} bytes cannot be stored", path_, size);
    Write(data, size);
    offsets_.push_back(offset_);
    sizes_.push_back(uint32_t(size));
    if (sync) sync_samples_.push_back(uint32_t(sizes_.size()));
    offset_ += size;
}

void Mp4Muxer::Finish() {
    if (file_ == nullptr) core::ThrowError("'{}': the video is already finished", path_);
    if (sizes_.empty()) core::ThrowError("'{}': a video needs at least one frame", path_);
    const uint32_t delta =
        uint32_t(std::max(1.0, std::round(double(kMp4VideoTimescale) / track_.fps)));
    const uint64_t duration = uint64_t(delta) * sizes_.size();
    const uint32_t movie_timescale = 1000;
    const uint64_t movie_duration =
        (duration * movie_timescale + kMp4VideoTimescale / 2) / kMp4VideoTimescale;
    const int version = movie_duration > 0xFFFFFFFFu ? 1 : 0;

    BoxWriter w;
    w.Begin("moov");
    w.BeginFull("mvhd", version, 0);
    if (version == 1) {
        w.U64(0);  // creation and modification times: none
        w.U64(0);
        w.U32(movie_timescale);
        w.U64(movie_duration);
    } else {
        w.U32(0);
        w.U32(0);
        w.U32(movie_timescale);
        w.U32(uint32_t(movie_duration));
    }
    w.U32(0x00010000);  // rate 1.0
    w.U16(0x0100);      // volume 1.0
    w.Zeros(10);
    w.UnityMatrix();
    w.Zeros(24);  // pre_defined
    w.U32(2);     // next_track_ID
    w.End();

    w.Begin("trak");
    w.BeginFull("tkhd", version, 3);  // enabled, in the movie
    if (version == 1) {
        w.U64(0);
        w.U64(0);
        w.U32(1);  // track_ID
        w.U32(0);
        w.U64(movie_duration);
    } else {
        w.U32(0);
        w.U32(0);
        w.U32(1);
        w.U32(0);
        w.U32(uint32_t(movie_duration));
    }
    w.Zeros(8);
    w.U16(0);  // layer
    w.U16(0);  // alternate_group
    w.U16(0);  // volume: a video track has none
    w.U16(0);
    w.UnityMatrix();
    w.U32(uint32_t(track_.width) << 16);  // 16.16 fixed point
    w.U32(uint32_t(track_.height) << 16);
    w.End();

    w.Begin("mdia");
    const int media_version = duration > 0xFFFFFFFFu ? 1 : 0;
    w.BeginFull("mdhd", media_version, 0);
    if (media_version == 1) {
        w.U64(0);
        w.U64(0);
        w.U32(kMp4VideoTimescale);
        w.U64(duration);
    } else {
        w.U32(0);
        w.U32(0);
        w.U32(kMp4VideoTimescale);
        w.U32(uint32_t(duration));
    }
    w.U16(0x55C4);  // language "und", packed ISO-639-2/T
    w.U16(0);
    w.End();
    w.BeginFull("hdlr", 0, 0);
    w.U32(0);
    w.Tag("vide");
    w.Zeros(12);
    for (char c : std::string("VideoHandler")) w.U8(uint8_t(c));
    w.U8(0);
    w.End();

    w.Begin("minf");
    w.BeginFull("vmhd", 0, 1);
    w.Zeros(8);  // graphicsmode, opcolor
    w.End();
    w.Begin("dinf");
    w.BeginFull("dref", 0, 0);
    w.U32(1);
    w.BeginFull("url ", 0, 1);  // the data is in this file
    w.End();
    w.End();
    w.End();

    w.Begin("stbl");
    w.BeginFull("stsd", 0, 0);
    w.U32(1);
    w.Begin("avc1");
    w.Zeros(6);
    w.U16(1);  // data_reference_index
    w.Zeros(16);
    w.U16(uint32_t(track_.width));
    w.U16(uint32_t(track_.height));
    w.U32(0x00480000);  // 72 dpi
    w.U32(0x00480000);
    w.U32(0);
    w.U16(1);       // frame_count per sample
    w.Zeros(32);    // compressorname
    w.U16(0x0018);  // depth: colour without alpha
    w.U16(0xFFFF);  // pre_defined = -1
    WriteAvcConfiguration(w, track_);
    w.End();
    w.End();
    w.BeginFull("stts", 0, 0);  // every frame lasts `delta` ticks
    w.U32(1);
    w.U32(uint32_t(sizes_.size()));
    w.U32(delta);
    w.End();
    w.BeginFull("stss", 0, 0);
    w.U32(uint32_t(sync_samples_.size()));
    for (uint32_t s : sync_samples_) w.U32(s);
    w.End();
    w.BeginFull("stsc", 0, 0);  // one sample per chunk, from the first chunk on
    w.U32(1);
    w.U32(1);
    w.U32(1);
    w.U32(1);
    w.End();
    w.BeginFull("stsz", 0, 0);
    w.U32(0);  // sizes differ: one per sample
    w.U32(uint32_t(sizes_.size()));
    for (uint32_t s : sizes_) w.U32(s);
    w.End();
    w.BeginFull("co64", 0, 0);
    w.U32(uint32_t(offsets_.size()));
    for (uint64_t o : offsets_) w.U64(o);
    w.End();
    w.End();  // stbl
    w.End();  // minf
    w.End();  // mdia
    w.End();  // trak
    w.End();  // moov

    Write(w.bytes().data(), w.bytes().size());
    // The mdat's 64-bit size: its 16-byte header and the samples.
    BoxWriter size;
    size.U64(offset_ - mdat_start_);
    if (fseeko(file_, off_t(mdat_start_ + 8), SEEK_SET) != 0)
        core::ThrowError("cannot write '{}': {}", path_, std::strerror(errno));
    Write(size.bytes().data(), size.bytes().size());
    FILE* file = file_;
    file_ = nullptr;
    if (std::fclose(file) != 0)
        core::ThrowError("cannot write '{}': {}", path_, std::strerror(errno));
}

}  // namespace io
}  // namespace t
}  // namespace open3d
