// Binary PLY read throughput (target: >= 300 MB/s on the 2-core CI machine for
// playbot_125k.ply). Reports bytes/s of the file as Google Benchmark's "bytes_per_second".
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include "open3d/t/io/PointCloudIO.h"

namespace {

void ReadPly(benchmark::State& state, const std::string& relative) {
    const std::string path = std::string(OPEN3D_DATA_DIR) + "/" + relative;
    if (!std::filesystem::exists(path)) {
        state.SkipWithError(("absent: " + path).c_str());
        return;
    }
    const auto bytes = static_cast<int64_t>(std::filesystem::file_size(path));
    for (auto _ : state) {
        open3d::t::geometry::PointCloud cloud;
        open3d::t::io::ReadPointCloud(path, cloud);
        benchmark::DoNotOptimize(cloud);
    }
    state.SetBytesProcessed(state.iterations() * bytes);
}

BENCHMARK_CAPTURE(ReadPly, playbot_125k, "playbot/playbot_125k.ply")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(ReadPly, biker_152k, "biker/biker_152k.ply")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(ReadPly, chair_splat, "chair/chair.splat")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
