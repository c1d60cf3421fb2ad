// Seed 001's vision half, measured (docs/seed001-vision.md); nothing here is
// a test and nothing asserts a speed.
//
//   cmake -S . -B build -DRIG_BUILD_BENCHMARKS=ON && cmake --build build -j2 --target vision_bench
//   build/bin/vision_bench                     ms per frame: rendered (emulator), measured (controller)
//   build/bin/vision_bench --density-survey    measured - true D per ROI, per cover class and fault
//   build/bin/vision_bench --frames DIR        PNGs of the left camera's frames with the ROIs drawn
//   build/bin/vision_bench --benchmark_filter=OverDds   ms per frame delivered over DDS (scripts/netns-run
//                                              around it keeps it in a loopback-only namespace)
//
// Frames: 1280 x 720, 2 x 2 samples per pixel, the default fields; each
// benchmark iteration renders the next frame of a boom driving north at
// 1.5 m/s and 30 fps, so the crop truth's tiles are built as new ground comes
// into view, as in a run.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "controller/boundary/vision/nozzle_vision.h"
#include "emulators/field2d/crop_cover_map.h"
#include "emulators/vision/camera_emulator.h"
#include "rig/camera/png_file.h"
#include "rig/host/child_process.h"
#include "rig/host/domain_lease.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"
#include "camera_frame_pattern.h"
#include "idl/topics.h"

namespace {

using rig::controller::boundary::BoundaryControllerConfig;
using rig::controller::boundary::vision::CameraVision;
using rig::controller::boundary::vision::FrameDensities;
using rig::controller::boundary::vision::seed001_vision_cameras;
using rig::controller::boundary::vision::VisionParams;
using rig::emulators::vision::BoomPose;
using rig::emulators::vision::CameraEmulator;
using rig::emulators::vision::CameraEmulatorParams;
using rig::field2d::CoverClass;
using rig::field2d::CropCoverMap;
using rig::field2d::CropCoverParams;
using rig::field2d::Vec2;

BoomPose pose_of_frame(std::uint64_t frame) { return BoomPose{{0.0, 1.5 / 30.0 * static_cast<double>(frame)}, 0.0, 0.5}; }

void render_frames(benchmark::State& state, CameraEmulatorParams params) {
    const CropCoverMap crop(CropCoverParams{}, 1);
    const CameraEmulator camera(std::move(params), 1, 0, "bench");
    std::uint64_t frame = 0;
    for (auto _ : state) {
        auto image = camera.render(crop, pose_of_frame(frame), frame);
        benchmark::DoNotOptimize(image);
        ++frame;
    }
}

void BM_RenderFrame(benchmark::State& state) { render_frames(state, rig::emulators::vision::seed001_camera_params(false)); }

// As the vision cases render (cases/seed001-table4-6-vision: one sample a pixel).
void BM_RenderFrameOneSample(benchmark::State& state) {
    CameraEmulatorParams params = rig::emulators::vision::seed001_camera_params(false);
    params.samples_per_axis = 1;
    render_frames(state, params);
}

void BM_RenderFrameDirtyLens(benchmark::State& state) {
    CameraEmulatorParams params = rig::emulators::vision::seed001_camera_params(false);
    params.faults.blur_radius_px = 4;
    render_frames(state, params);
}

// The controller's work per frame and camera: Otsu over the frame, three ROI warps, Eq. 15-17.
void BM_MeasureFrame(benchmark::State& state) {
    const CropCoverMap crop(CropCoverParams{}, 1);
    const CameraEmulator camera(rig::emulators::vision::seed001_camera_params(false), 1, 0, "bench");
    const auto image = camera.render(crop, pose_of_frame(0), 0);
    const CameraVision vision(seed001_vision_cameras(BoundaryControllerConfig{})[0], VisionParams{});
    for (auto _ : state) {
        FrameDensities result = vision.measure(&*image, 0.5);
        benchmark::DoNotOptimize(result);
    }
}

// A process's resident set now and at its peak (kB), from /proc/PID/status.
std::pair<double, double> rss_kb(const std::string& pid = "self") {
    std::ifstream status("/proc/" + pid + "/status");
    std::string key;
    double rss = 0.0;
    double peak = 0.0;
    while (status >> key) {
        if (key == "VmRSS:") status >> rss;
        else if (key == "VmHWM:") status >> peak;
        status.ignore(1 << 16, '\n');
    }
    return {rss, peak};
}

template <class Ready>
void wait_matched(Ready ready) {
    const rig::WallStopwatch waited;
    while (!ready()) {
        if (waited.elapsed() > std::chrono::milliseconds(60'000)) throw std::runtime_error("DDS endpoints never matched");
        rig::pause_between_polls(std::chrono::milliseconds(5));
    }
}

// The timed loop both DDS benchmarks share: a frame (its pixels made once,
// outside the loop) published and acknowledged by every matched reader, then
// `taken` (the answer that it was taken) awaited; the resident set after.
template <class Taken>
void deliver_frames(benchmark::State& state, rig::Writer<rig::msg::CameraFrame>& writer, Taken taken) {
    rig::msg::CameraFrame frame = rig::testing::patterned_frame(0, 1280, 720);
    std::uint32_t number = 0;
    for (auto _ : state) {
        frame.frame_number(number++);
        writer.publish(frame);
        if (!writer.wait_delivered(std::chrono::milliseconds(60'000))) state.SkipWithError("frame not acknowledged");
        if (!taken()) state.SkipWithError("frame not taken");
    }
    state.counters["rss_MB"] = rss_kb().first / 1024.0;
    state.counters["peak_rss_MB"] = rss_kb().second / 1024.0;
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * 1280 * 720 * 3);
}

// One 1280 x 720 frame from the camera's participant to the controller's, both
// in this process (Fast DDS delivers in process, no transport): publish, wait
// until the reader has acknowledged it (it is in the reader's history, as
// lockstep waits), take it.
void BM_DeliverFrameOverDds(benchmark::State& state) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext camera(lease.domain_id(), "camera");
    rig::DdsContext controller(lease.domain_id(), "controller");
    const double rss_before_kb = rss_kb().first;
    rig::Writer<rig::msg::CameraFrame> writer(camera, rig::topics::kCameraLeftFrame);
    rig::Reader<rig::msg::CameraFrame> reader(controller, rig::topics::kCameraLeftFrame);
    state.counters["endpoints_MB"] = (rss_kb().first - rss_before_kb) / 1024.0;
    wait_matched([&] { return writer.matched_readers() >= 1 && reader.matched_writers() >= 1; });
    deliver_frames(state, writer, [&] {
        std::size_t frames = 0;
        while (frames == 0 && reader.wait_for_data(std::chrono::milliseconds(60'000))) frames = reader.take_all().size();
        return frames == 1;
    });
}

// The same frame to a reader in another process (tests/camera_frame_node.cpp
// --sink): through the transports as RTPS fragments. Publish, wait until that
// reader has acknowledged it, then until the sink says it took it (a small
// sample back): without that answer this writer would outrun the sink's take
// loop and the frames pile up in its keep-all history.
void BM_DeliverFrameOverDdsAcrossProcesses(benchmark::State& state) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext camera(lease.domain_id(), "camera");
    const double rss_before_kb = rss_kb().first;
    rig::Writer<rig::msg::CameraFrame> writer(camera, rig::topics::kCameraLeftFrame);
    state.counters["endpoints_MB"] = (rss_kb().first - rss_before_kb) / 1024.0;
    rig::Reader<rig::msg::NmeaSentence> taken(camera, "test/frame_taken");
    rig::ChildProcess sink({RIG_CAMERA_FRAME_NODE, "--domain", std::to_string(lease.domain_id()), "--sink"},
                           "/dev/null");
    wait_matched([&] { return writer.matched_readers() >= 1 && taken.matched_writers() >= 1; });
    deliver_frames(state, writer, [&] {
        std::size_t answers = 0;
        while (answers == 0 && taken.wait_for_data(std::chrono::milliseconds(60'000))) answers = taken.take_all().size();
        return answers == 1;
    });
    state.counters["sink_peak_rss_MB"] = rss_kb(std::to_string(sink.pid())).second / 1024.0;
    writer.publish(rig::testing::patterned_frame(0xffffffffu, 0, 0));  // the sink's stop
    writer.wait_delivered(std::chrono::milliseconds(60'000));
    sink.stop(std::chrono::milliseconds(10'000));
}

BENCHMARK(BM_RenderFrame)->Unit(benchmark::kMillisecond)->MinTime(3.0);
BENCHMARK(BM_RenderFrameOneSample)->Unit(benchmark::kMillisecond)->MinTime(3.0);
BENCHMARK(BM_RenderFrameDirtyLens)->Unit(benchmark::kMillisecond)->MinTime(3.0);
BENCHMARK(BM_MeasureFrame)->Unit(benchmark::kMillisecond)->MinTime(3.0);
BENCHMARK(BM_DeliverFrameOverDds)->Unit(benchmark::kMillisecond)->MinTime(3.0)->UseRealTime();
BENCHMARK(BM_DeliverFrameOverDdsAcrossProcesses)->Unit(benchmark::kMillisecond)->MinTime(3.0)->UseRealTime();

struct SurveyCase {
    const char* name;
    CameraEmulatorParams camera;
};

// Measured minus true D per ROI over seeds 1-10, both cameras, three places
// per seed (heading 0, 15, 30 deg to the rows), for each cover class.
int density_survey() {
    std::vector<SurveyCase> cases;
    cases.push_back({"healthy", CameraEmulatorParams{}});
    SurveyCase blur{"blur_radius_px 4", CameraEmulatorParams{}};
    blur.camera.faults.blur_radius_px = 4;
    cases.push_back(blur);
    SurveyCase cast{"colour_cast 1.35/1.0/0.65", CameraEmulatorParams{}};
    cast.camera.faults.colour_cast = {1.35, 1.0, 0.65};
    cases.push_back(cast);
    SurveyCase dim{"lighting_gain 0.5", CameraEmulatorParams{}};
    dim.camera.lighting_gain = 0.5;
    cases.push_back(dim);
    SurveyCase pitch{"pitch_offset_deg +5", CameraEmulatorParams{}};
    pitch.camera.faults.pitch_offset_deg = 5.0;
    cases.push_back(pitch);

    const std::vector<rig::controller::boundary::vision::VisionCameraConfig> cameras = seed001_vision_cameras(BoundaryControllerConfig{});
    std::printf("%-26s %-7s %5s %8s %8s %8s %8s %8s\n", "camera", "cover", "ROIs", "true_D", "meas_D", "mean_err", "sd_err", "max|err|");
    for (const SurveyCase& survey : cases) {
        for (const CoverClass cover : {CoverClass::bare, CoverClass::sparse, CoverClass::normal}) {
            std::vector<double> errors;
            double true_sum = 0.0;
            double measured_sum = 0.0;
            for (std::uint64_t seed = 1; seed <= 10; ++seed) {
                CropCoverParams params;
                params.default_cover = cover;
                const CropCoverMap crop(params, seed);
                for (int side = 0; side < 2; ++side) {
                    CameraEmulatorParams emulated = survey.camera;
                    emulated.camera = rig::camera::seed001_boom_camera(side == 1);
                    const CameraEmulator camera(emulated, seed, static_cast<std::uint64_t>(side), side == 0 ? "left" : "right");
                    const CameraVision vision(cameras[static_cast<std::size_t>(side)], VisionParams{});
                    for (int place = 0; place < 3; ++place) {
                        const BoomPose pose{{5.0 * place, 3.0 * place}, 15.0 * place, 0.5};
                        const auto image = camera.render(crop, pose, static_cast<std::uint64_t>(place));
                        const FrameDensities result = vision.measure(image ? &*image : nullptr, 0.5);
                        for (const auto& nozzle : result.nozzles) {
                            if (!nozzle.measured) continue;
                            const double truth = crop.cover_fraction(
                                rig::field2d::nozzle_roi_ground(pose.boom_centre_ground, pose.heading_deg, (nozzle.nozzle - 2.5) * 0.5));
                            errors.push_back(nozzle.density - truth);
                            true_sum += truth;
                            measured_sum += nozzle.density;
                        }
                    }
                }
            }
            const double n = static_cast<double>(errors.size());
            double mean = 0.0;
            double worst = 0.0;
            for (const double e : errors) {
                mean += e / n;
                worst = std::max(worst, std::abs(e));
            }
            double variance = 0.0;
            for (const double e : errors) variance += (e - mean) * (e - mean) / (n - 1.0);
            std::printf("%-26s %-7s %5zu %8.4f %8.4f %+8.4f %8.4f %8.4f\n", survey.name, rig::field2d::cover_class_name(cover), errors.size(),
                        true_sum / n, measured_sum / n, mean, std::sqrt(variance), worst);
        }
    }
    return 0;
}

// The left camera's frames of a field whose cover changes along travel
// (bare, sparse, normal in 2 m bands), healthy and with each fault, the
// controller's ROIs drawn in magenta with the measured D beside the true D;
// and its calibration frames (boards, chessboards).
int write_frames(const std::string& directory) {
    CropCoverParams params;
    params.default_cover = CoverClass::normal;
    params.patches.push_back({rig::field2d::Polygon({{-5, -1}, {5, -1}, {5, 2}, {-5, 2}}, "bare"), CoverClass::bare});
    params.patches.push_back({rig::field2d::Polygon({{-5, 2}, {5, 2}, {5, 4}, {-5, 4}}, "sparse"), CoverClass::sparse});
    const CropCoverMap crop(params, 1);
    const auto config = seed001_vision_cameras(BoundaryControllerConfig{})[0];
    const CameraVision vision(config, VisionParams{});
    std::vector<std::pair<std::string, CameraEmulatorParams>> cameras;
    cameras.emplace_back("healthy", rig::emulators::vision::seed001_camera_params(false));
    cameras.emplace_back("pitch_plus5", cameras[0].second);
    cameras.back().second.faults.pitch_offset_deg = 5.0;
    cameras.emplace_back("blur4", cameras[0].second);
    cameras.back().second.faults.blur_radius_px = 4;
    cameras.emplace_back("low_sun", cameras[0].second);
    cameras.back().second.faults.colour_cast = {1.35, 1.0, 0.65};
    for (const auto& [name, params_of_camera] : cameras) {
        const CameraEmulator camera(params_of_camera, 1, 0, "left");
        for (const double north : {0.0, 2.0, 4.0, 1.6}) {
            const BoomPose pose{{0.0, north}, 0.0, 0.5};
            auto frame = camera.render(crop, pose, 0);
            const FrameDensities result = vision.measure(&*frame, 0.5);
            std::printf("%-12s boom at %.1f m:", name.c_str(), north);
            for (const auto& nozzle : result.nozzles) {
                const double truth = crop.cover_fraction(
                    rig::field2d::nozzle_roi_ground(pose.boom_centre_ground, pose.heading_deg, (nozzle.nozzle - 2.5) * 0.5));
                std::printf("  nozzle %d D %.3f (true %.3f)", nozzle.nozzle, nozzle.density, truth);
                rig::camera::draw_quad(*frame, nozzle.roi.image_px, rig::camera::Rgb{255, 0, 255}, 3);
            }
            std::printf("\n");
            char file[64];
            std::snprintf(file, sizeof file, "/left_%s_%04.1fm.png", name.c_str(), north);
            rig::camera::write_png(directory + file, *frame);
        }
    }
    rig::emulators::vision::CalibrationBoards boards;
    boards.boom_board_right_m = config.model.mounting.right_m;
    boards.nozzle_right_m = config.nozzle_right_m;
    CropCoverParams bare;
    bare.default_cover = CoverClass::bare;
    const auto calibration = CameraEmulator(cameras[0].second, 1, 0, "left").render_calibration(CropCoverMap(bare, 1), BoomPose{}, boards, 0);
    rig::camera::write_png(directory + "/left_calibration.png", *calibration);
    rig::emulators::vision::Chessboard board;
    board.origin_right_m = config.model.mounting.right_m - 3 * board.square_m;
    board.origin_ahead_m = 0.10;
    const CameraEmulator camera(cameras[0].second, 1, 0, "left");
    rig::camera::write_png(directory + "/left_chessboard_boom_plane.png", *camera.render_chessboard(CropCoverMap(bare, 1), BoomPose{}, board, 0));
    board.square_m = 0.060;
    board.origin_right_m = config.model.mounting.right_m - 3 * board.square_m;
    board.origin_ahead_m = 0.25;
    board.on_ground = true;
    rig::camera::write_png(directory + "/left_chessboard_ground.png", *camera.render_chessboard(CropCoverMap(bare, 1), BoomPose{}, board, 0));
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--density-survey") == 0) return density_survey();
        if (std::strcmp(argv[i], "--frames") == 0 && i + 1 < argc) return write_frames(argv[i + 1]);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
