// The far process of tests/camera_frame_dds_test.cpp and of vision_bench's
// BM_DeliverFrameOverDdsAcrossProcesses: camera frames between two processes
// cross the shared-memory transport (or UDP on 127.0.0.1), which two
// participants of one process never do (Fast DDS delivers those in process).
//
//   camera_frame_node --domain D --echo   every frame read on the left camera's topic written back on the right's
//   camera_frame_node --domain D --sink   every frame read, dropped and answered on test/frame_taken with its
//                                         number (the benchmark's reader: the writer waits for the answer, so
//                                         frames cannot pile up unread in this reader's keep-all history)
//
// Exits 0 after the frame numbered kStopFrame (not echoed), 3 when nothing
// arrives for 120 s (its parent is gone), 4 when the echo writer never matched.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "idl/topics.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"

namespace {
constexpr std::uint32_t kStopFrame = 0xffffffffu;
}

int main(int argc, char** argv) {
    std::uint32_t domain = 0;
    bool echo = false;
    for (int i = 1; i < argc; ++i) {
        const std::string key = argv[i];
        if (key == "--domain" && i + 1 < argc) domain = static_cast<std::uint32_t>(std::stoul(argv[++i]));
        else if (key == "--echo") echo = true;
        else if (key == "--sink") echo = false;
    }
    rig::DdsContext dds(domain, echo ? "camera-frame-echo" : "camera-frame-sink");
    rig::Reader<rig::msg::CameraFrame> frames(dds, rig::topics::kCameraLeftFrame);
    std::unique_ptr<rig::Writer<rig::msg::CameraFrame>> back;
    std::unique_ptr<rig::Writer<rig::msg::NmeaSentence>> taken;
    if (echo) back = std::make_unique<rig::Writer<rig::msg::CameraFrame>>(dds, rig::topics::kCameraRightFrame);
    else taken = std::make_unique<rig::Writer<rig::msg::NmeaSentence>>(dds, "test/frame_taken");
    if (back || taken) {
        // Volatile durability: an answer written before the parent's reader (made
        // before this process started) matched this writer would be lost.
        const rig::WallStopwatch waited;
        while ((back ? back->matched_readers() : taken->matched_readers()) < 1) {
            if (waited.elapsed() > std::chrono::milliseconds(60'000)) return 4;
            rig::pause_between_polls(std::chrono::milliseconds(5));
        }
    }
    std::uint64_t seen = 0;
    for (;;) {
        if (!frames.wait_for_data(std::chrono::milliseconds(120'000))) {
            std::fprintf(stderr, "camera_frame_node: nothing for 120 s after %llu frames\n",
                         static_cast<unsigned long long>(seen));
            return 3;
        }
        for (const rig::msg::CameraFrame& frame : frames.take_all()) {
            if (frame.frame_number() == kStopFrame) {
                std::fprintf(stderr, "camera_frame_node: stop after %llu frames\n", static_cast<unsigned long long>(seen));
                // Whatever was echoed is acknowledged before the participant goes.
                if (back && !back->wait_delivered(std::chrono::milliseconds(60'000))) return 4;
                return 0;
            }
            ++seen;
            if (back) back->publish(frame);
            if (taken) {
                rig::msg::NmeaSentence answer;
                answer.sentence(std::to_string(frame.frame_number()));
                taken->publish(answer);
            }
        }
    }
}
