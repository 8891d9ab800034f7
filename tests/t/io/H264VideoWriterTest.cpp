// H264VideoWriter and Mp4Muxer: the file is read back box by box here (not through the
// writer's code), its samples are decoded by openh264, a decoder independent of the x264
// encoder, and the decoded planes are compared with the frames' BT.709 values computed here.
#include <gtest/gtest.h>
#include <wels/codec_api.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/io/H264VideoWriter.h"
#include "open3d/t/io/Mp4Muxer.h"

namespace {

using open3d::t::io::H264VideoOptions;
using open3d::t::io::H264VideoWriter;
namespace fs = std::filesystem;

std::vector<uint8_t> ReadBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

uint64_t BigEndian(const std::vector<uint8_t>& b, size_t at, int bytes) {
    uint64_t v = 0;
    for (int k = 0; k < bytes; ++k) v = (v << 8) | b.at(at + k);
    return v;
}

// Every box of the file by its path ("moov/trak/mdia/minf/stbl/stsz"): [payload begin, end).
// Containers are descended into; stsd's entry and avc1's avcC are reached by their offsets.
using Boxes = std::multimap<std::string, std::pair<size_t, size_t>>;
void WalkBoxes(const std::vector<uint8_t>& b, size_t begin, size_t end, const std::string& parent,
               Boxes& boxes) {
    static const std::vector<std::string> containers = {"moov", "trak", "mdia",
                                                        "minf", "stbl", "dinf"};
    size_t at = begin;
    while (at < end) {
        ASSERT_LE(at + 8, end) << "box header past its parent at " << at;
        uint64_t size = BigEndian(b, at, 4);
        const std::string type(b.begin() + at + 4, b.begin() + at + 8);
        size_t header = 8;
        if (size == 1) {
            size = BigEndian(b, at + 8, 8);
            header = 16;
        }
        ASSERT_GE(size, header) << type;
        ASSERT_LE(at + size, end) << type << " runs past its parent";
        const std::string path = parent.empty() ? type : parent + "/" + type;
        boxes.emplace(path, std::make_pair(at + header, size_t(at + size)));
        for (const std::string& c : containers) {
            if (type == c) WalkBoxes(b, at + header, at + size, path, boxes);
        }
        at += size;
    }
    ASSERT_EQ(at, end);
}

struct ParsedVideo {
    int width = 0, height = 0;  // avc1 sample entry
    uint32_t timescale = 0;
    uint64_t duration = 0;  // mdhd, in timescale ticks
    uint32_t sample_delta = 0;
    std::vector<uint32_t> sizes;
    std::vector<uint64_t> offsets;
    std::vector<uint32_t> sync;
    std::vector<uint8_t> sps, pps;
    std::vector<std::string> top_level;
};

ParsedVideo Parse(const std::vector<uint8_t>& b) {
    Boxes boxes;
    WalkBoxes(b, 0, b.size(), "", boxes);
    ParsedVideo v;
    size_t at = 0;
    while (at < b.size()) {
        v.top_level.emplace_back(b.begin() + at + 4, b.begin() + at + 8);
        uint64_t size = BigEndian(b, at, 4);
        if (size == 1) size = BigEndian(b, at + 8, 8);
        at += size;
    }
    const std::string stbl = "moov/trak/mdia/minf/stbl/";
    auto payload = [&](const std::string& path) {
        EXPECT_EQ(boxes.count(path), 1u) << path;
        return boxes.find(path)->second.first;
    };
    const size_t mdhd = payload("moov/trak/mdia/mdhd");
    v.timescale = uint32_t(BigEndian(b, mdhd + 12, 4));
    v.duration = BigEndian(b, mdhd + 16, 4);
    // stsd: version/flags, entry count, then the avc1 entry: 8-byte header, 24 bytes, size.
    const size_t avc1 = payload(stbl + "stsd") + 8;
    EXPECT_EQ(std::string(b.begin() + avc1 + 4, b.begin() + avc1 + 8), "avc1");
    v.width = int(BigEndian(b, avc1 + 8 + 24, 2));
    v.height = int(BigEndian(b, avc1 + 8 + 26, 2));
    const size_t avcc = avc1 + 8 + 78;  // the sample entry's fields take 78 bytes
    EXPECT_EQ(std::string(b.begin() + avcc + 4, b.begin() + avcc + 8), "avcC");
    const size_t record = avcc + 8;
    EXPECT_EQ(b[record + 4] & 3, 3) << "NAL sizes of 4 bytes";
    EXPECT_EQ(b[record + 5] & 31, 1) << "one SPS";
    const size_t sps_size = BigEndian(b, record + 6, 2);
    v.sps.assign(b.begin() + record + 8, b.begin() + record + 8 + sps_size);
    const size_t pps_at = record + 8 + sps_size;
    EXPECT_EQ(b[pps_at], 1) << "one PPS";
    const size_t pps_size = BigEndian(b, pps_at + 1, 2);
    v.pps.assign(b.begin() + pps_at + 3, b.begin() + pps_at + 3 + pps_size);
    const size_t stts = payload(stbl + "stts");
    EXPECT_EQ(BigEndian(b, stts + 4, 4), 1u);
    v.sample_delta = uint32_t(BigEndian(b, stts + 12, 4));
    const size_t stsz = payload(stbl + "stsz");
    EXPECT_EQ(BigEndian(b, stsz + 4, 4), 0u);
    const size_t count = BigEndian(b, stsz + 8, 4);
    EXPECT_EQ(BigEndian(b, stts + 8, 4), count);
    for (size_t k = 0; k < count; ++k)
        v.sizes.push_back(uint32_t(BigEndian(b, stsz + 12 + 4 * k, 4)));
    const size_t co64 = payload(stbl + "co64");
    EXPECT_EQ(BigEndian(b, co64 + 4, 4), count);
    for (size_t k = 0; k < count; ++k) v.offsets.push_back(BigEndian(b, co64 + 8 + 8 * k, 8));
    const size_t stss = payload(stbl + "stss");
    const size_t syncs = BigEndian(b, stss + 4, 4);
    for (size_t k = 0; k < syncs; ++k)
        v.sync.push_back(uint32_t(BigEndian(b, stss + 8 + 4 * k, 4)));
    // The samples lie inside mdat, in order, without gaps.
    const auto mdat = boxes.find("mdat")->second;
    uint64_t expected = mdat.first;
    for (size_t k = 0; k < count; ++k) {
        EXPECT_EQ(v.offsets[k], expected) << "sample " << k;
        expected += v.sizes[k];
    }
    EXPECT_EQ(expected, mdat.second);
    return v;
}

struct Planes {
    int width = 0, height = 0;
    std::vector<uint8_t> y, cb, cr;
};

// The planes of a decoded frame, copied out of the decoder's buffers.
Planes Copy(uint8_t* const data[3], const SBufferInfo& info) {
    Planes p;
    const SSysMEMBuffer& sb = info.UsrData.sSystemBuffer;
    p.width = sb.iWidth;
    p.height = sb.iHeight;
    for (int row = 0; row < p.height; ++row) {
        const uint8_t* y = data[0] + size_t(row) * sb.iStride[0];
        p.y.insert(p.y.end(), y, y + p.width);
    }
    for (int row = 0; row < p.height / 2; ++row) {
        const uint8_t* cb = data[1] + size_t(row) * sb.iStride[1];
        const uint8_t* cr = data[2] + size_t(row) * sb.iStride[1];
        p.cb.insert(p.cb.end(), cb, cb + p.width / 2);
        p.cr.insert(p.cr.end(), cr, cr + p.width / 2);
    }
    return p;
}

// Decodes every sample with openh264: the parameter sets, then each frame, with Annex B start
// codes in place of the 4-byte sizes.
std::vector<Planes> Decode(const std::vector<uint8_t>& file, const ParsedVideo& v) {
    ISVCDecoder* decoder = nullptr;
    EXPECT_EQ(WelsCreateDecoder(&decoder), 0);
    SDecodingParam param = {};
    param.sVideoProperty.eVideoBsType = VIDEO_BITSTREAM_AVC;
    EXPECT_EQ(decoder->Initialize(&param), 0);
    const uint8_t start[4] = {0, 0, 0, 1};
    std::vector<Planes> frames;
    auto decode = [&](const std::vector<uint8_t>& annex_b) {
        uint8_t* data[3] = {nullptr, nullptr, nullptr};
        SBufferInfo info = {};
        const DECODING_STATE state =
            decoder->DecodeFrameNoDelay(annex_b.data(), int(annex_b.size()), data, &info);
        EXPECT_EQ(state, dsErrorFree);
        if (info.iBufferStatus == 1) frames.push_back(Copy(data, info));
    };
    std::vector<uint8_t> headers(start, start + 4);
    headers.insert(headers.end(), v.sps.begin(), v.sps.end());
    headers.insert(headers.end(), start, start + 4);
    headers.insert(headers.end(), v.pps.begin(), v.pps.end());
    decode(headers);
    for (size_t k = 0; k < v.sizes.size(); ++k) {
        std::vector<uint8_t> annex_b;
        size_t at = v.offsets[k];
        const size_t end = at + v.sizes[k];
        while (at < end) {
            const size_t nal = BigEndian(file, at, 4);
            annex_b.insert(annex_b.end(), start, start + 4);
            annex_b.insert(annex_b.end(), file.begin() + at + 4, file.begin() + at + 4 + nal);
            at += 4 + nal;
        }
        EXPECT_EQ(at, end) << "sample " << k << ": NAL sizes do not add up";
        decode(annex_b);
    }
    // The end of the stream: the decoder hands over the frames it holds for reordering.
    int remaining = 0;
    decoder->GetOption(DECODER_OPTION_NUM_OF_FRAMES_REMAINING_IN_BUFFER, &remaining);
    for (int k = 0; k < remaining; ++k) {
        uint8_t* data[3] = {nullptr, nullptr, nullptr};
        SBufferInfo info = {};
        decoder->FlushFrame(data, &info);
        if (info.iBufferStatus == 1) frames.push_back(Copy(data, info));
    }
    decoder->Uninitialize();
    WelsDestroyDecoder(decoder);
    return frames;
}

// A smooth moving picture: gradients and a soft disc that moves with the frame number.
std::vector<uint8_t> TestFrame(int w, int h, int channels, int frame) {
    std::vector<uint8_t> rgb(size_t(w) * h * channels, 255);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const double dx = x - (10.0 + 2.0 * frame), dy = y - h / 2.0;
            const double disc = std::exp(-(dx * dx + dy * dy) / 60.0);
            uint8_t* p = &rgb[(size_t(y) * w + x) * channels];
            p[0] = uint8_t(std::lround(40 + 150.0 * x / w + 60 * disc));
            p[1] = uint8_t(std::lround(30 + 120.0 * y / h + 40 * disc));
            p[2] = uint8_t(std::lround(200 - 120.0 * x / w));
        }
    }
    return rgb;
}

double Psnr(const std::vector<double>& a, const std::vector<uint8_t>& b) {
    double sum = 0;
    for (size_t k = 0; k < a.size(); ++k) sum += (a[k] - b[k]) * (a[k] - b[k]);
    return 10.0 * std::log10(255.0 * 255.0 / std::max(sum / double(a.size()), 1e-12));
}

// Writes `frames` frames of w x h, reads the file back and decodes it; returns the decoded
// planes' PSNR against BT.709 limited-range values computed here (the worst plane and frame).
double WriteAndCheck(const fs::path& path, int w, int h, int channels, int frames, double fps,
                     const H264VideoOptions& options = {}) {
    {
        H264VideoWriter writer(path.string(), w, h, fps, options);
        for (int f = 0; f < frames; ++f)
            writer.WriteFrame(TestFrame(w, h, channels, f).data(), channels);
        EXPECT_EQ(writer.Finish(), size_t(frames));
    }
    const std::vector<uint8_t> file = ReadBytes(path.string());
    const ParsedVideo v = Parse(file);
    const int cw = w + (w & 1), ch = h + (h & 1);
    EXPECT_EQ(v.top_level, (std::vector<std::string>{"ftyp", "mdat", "moov"}));
    EXPECT_EQ(v.width, cw);
    EXPECT_EQ(v.height, ch);
    EXPECT_EQ(v.sizes.size(), size_t(frames));
    EXPECT_EQ(v.timescale, open3d::t::io::kMp4VideoTimescale);
    EXPECT_EQ(v.sample_delta, uint32_t(std::lround(v.timescale / fps)));
    EXPECT_EQ(v.duration, uint64_t(v.sample_delta) * frames);
    EXPECT_FALSE(v.sync.empty());
    if (!v.sync.empty()) EXPECT_EQ(v.sync[0], 1u) << "the first frame is an IDR frame";
    const std::vector<Planes> decoded = Decode(file, v);
    EXPECT_EQ(decoded.size(), size_t(frames));
    double worst = 1e9;
    for (size_t f = 0; f < decoded.size(); ++f) {
        EXPECT_EQ(decoded[f].width, cw);
        EXPECT_EQ(decoded[f].height, ch);
        const std::vector<uint8_t> rgb = TestFrame(w, h, channels, int(f));
        // Padding repeats the last column and row.
        auto pixel = [&](int x, int y) {
            return &rgb[(size_t(std::min(y, h - 1)) * w + std::min(x, w - 1)) * channels];
        };
        auto luma_of = [](double r, double g, double b) {
            return 0.2126 * r + 0.7152 * g + 0.0722 * b;
        };
        std::vector<double> luma, cb, cr;
        for (int y = 0; y < ch; ++y) {
            for (int x = 0; x < cw; ++x) {
                const uint8_t* p = pixel(x, y);
                luma.push_back(16.0 + 219.0 / 255.0 * luma_of(p[0], p[1], p[2]));
            }
        }
        for (int y = 0; y < ch; y += 2) {
            for (int x = 0; x < cw; x += 2) {  // chroma of the 2x2 block's mean colour
                double m[3] = {0, 0, 0};
                for (int k = 0; k < 4; ++k)
                    for (int c = 0; c < 3; ++c) m[c] += pixel(x + k % 2, y + k / 2)[c] / 4.0;
                const double l = luma_of(m[0], m[1], m[2]);
                cb.push_back(128.0 + 224.0 / 255.0 * (m[2] - l) / (2.0 * (1.0 - 0.0722)));
                cr.push_back(128.0 + 224.0 / 255.0 * (m[0] - l) / (2.0 * (1.0 - 0.2126)));
            }
        }
        const double y_db = Psnr(luma, decoded[f].y), cb_db = Psnr(cb, decoded[f].cb),
                     cr_db = Psnr(cr, decoded[f].cr);
        if (std::getenv("H264_TEST_PRINT"))
            std::printf("frame %zu: Y %.2f Cb %.2f Cr %.2f dB\n", f, y_db, cb_db, cr_db);
        worst = std::min({worst, y_db, cb_db, cr_db});
    }
    return worst;
}

class H264VideoWriterTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::path(::testing::TempDir()) /
               ("h264_" +
                std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    fs::path dir_;
};

// Measured on these frames (H264_TEST_PRINT=1 prints each plane): CRF 23 gives 43.0-49.1 dB
// per plane and frame, CRF 1 55.5-58.1 dB (the writer's rounding to bytes alone allows ~59).
// BT.601 weights instead of BT.709 move luma by up to ~10 levels here: below 30 dB.
TEST_F(H264VideoWriterTest, DecodesToTheFramesItWasGiven) {
    EXPECT_GT(WriteAndCheck(dir_ / "v.mp4", 64, 48, 3, 12, 30.0), 40.0);
}

TEST_F(H264VideoWriterTest, FinestRateDecodesToTheConvertedPlanes) {
    H264VideoOptions fine;
    fine.crf = 1;
    EXPECT_GT(WriteAndCheck(dir_ / "v.mp4", 64, 48, 4, 5, 24.0, fine), 52.0);
}

TEST_F(H264VideoWriterTest, OddSizesArePaddedByTheirEdge) {
    EXPECT_GT(WriteAndCheck(dir_ / "v.mp4", 63, 47, 4, 6, 29.97), 40.0);
}

TEST_F(H264VideoWriterTest, UnfinishedVideoLeavesNoFile) {
    const fs::path path = dir_ / "v.mp4";
    {
        H264VideoWriter writer(path.string(), 32, 32, 10.0);
        writer.WriteFrame(TestFrame(32, 32, 3, 0).data(), 3);
    }
    EXPECT_TRUE(fs::is_empty(dir_)) << "neither the video nor its temporary is left";
}

TEST_F(H264VideoWriterTest, RefusesWhatItCannotWrite) {
    const std::string path = (dir_ / "v.mp4").string();
    EXPECT_THROW(H264VideoWriter(path, 0, 32, 10.0), open3d::core::Open3DError);
    EXPECT_THROW(H264VideoWriter(path, 32, 32, 0.0), open3d::core::Open3DError);
    H264VideoOptions bad_preset;
    bad_preset.preset = "warp";
    try {
        H264VideoWriter writer(path, 32, 32, 10.0, bad_preset);
        FAIL() << "an unknown preset was accepted";
    } catch (const open3d::core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("--preset 'warp' is not an x264 preset (ultrafast,"),
                  std::string::npos);
    }
    H264VideoWriter writer(path, 32, 32, 10.0);
    EXPECT_THROW(writer.WriteFrame(TestFrame(32, 32, 3, 0).data(), 2), open3d::core::Open3DError);
    EXPECT_THROW((H264VideoWriter((dir_ / "no" / "v.mp4").string(), 32, 32, 10.0)),
                 open3d::core::Open3DError);
}

}  // namespace
