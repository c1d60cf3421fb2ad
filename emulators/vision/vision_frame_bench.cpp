// Milliseconds per rendered camera frame (seed 001, 1280 x 720, 2 x 2 samples
// per pixel, the default normal-cover field), with Google Benchmark. A
// measurement for docs/seed001-vision.md, not a test: nothing asserts a speed.
//
//   cmake -S . -B build -DRIG_BUILD_BENCHMARKS=ON && cmake --build build -j2 --target vision_frame_bench
//   build/bin/vision_frame_bench
//
// Each iteration renders the next frame of a boom driving north at 1.5 m/s and
// 30 fps, so the crop truth's tiles are built as new ground comes into view,
// as they are in a run.
#include <benchmark/benchmark.h>

#include <cstdint>

#include "emulators/field2d/crop_cover_map.h"
#include "emulators/vision/camera_emulator.h"

namespace {

using rig::emulators::vision::BoomPose;
using rig::emulators::vision::CameraEmulator;
using rig::emulators::vision::CameraEmulatorParams;

void render_frames(benchmark::State& state, CameraEmulatorParams params) {
    const rig::field2d::CropCoverMap crop(rig::field2d::CropCoverParams{}, 1);
    const CameraEmulator camera(std::move(params), 1, 0, "bench");
    std::uint64_t frame = 0;
    for (auto _ : state) {
        const BoomPose pose{{0.0, 1.5 / 30.0 * static_cast<double>(frame)}, 0.0, 0.5};
        auto image = camera.render(crop, pose, frame);
        benchmark::DoNotOptimize(image);
        ++frame;
    }
    state.counters["frames"] = static_cast<double>(frame);
}

void BM_RenderFrame(benchmark::State& state) {
    render_frames(state, rig::emulators::vision::seed001_camera_params(false));
}

void BM_RenderFrameDirtyLens(benchmark::State& state) {
    CameraEmulatorParams params = rig::emulators::vision::seed001_camera_params(false);
    params.faults.blur_radius_px = 4;
    render_frames(state, params);
}

}  // namespace

BENCHMARK(BM_RenderFrame)->Unit(benchmark::kMillisecond)->MinTime(3.0);
BENCHMARK(BM_RenderFrameDirtyLens)->Unit(benchmark::kMillisecond)->MinTime(3.0);
BENCHMARK_MAIN();
