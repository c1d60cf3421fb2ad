// Seed 001's camera frames on the rig's DDS set-up (issue 13 item 2): a
// 1280 x 720 RGB frame is 2.8 MB, far beyond one RTPS datagram, and its type's
// bound (sequence<octet, 11059200>) is 11 MB. The frames must arrive bit for
// bit, in order, none lost, with the project's reliable keep-all QoS, between
// two participants of one process (Fast DDS's in-process delivery) and between
// two processes (shared memory or UDP on 127.0.0.1, as RTPS fragments); a frame
// at either end of the size bound is delivered, one past it refused by name.
// Nothing here measures speed (vision_bench's BM_DeliverFrameOverDds does).
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "camera_frame_pattern.h"
#include "idl/topics.h"
#include "rig/host/child_process.h"
#include "rig/host/domain_lease.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"

namespace {

using rig::msg::CameraFrame;
using rig::testing::is_patterned;
using rig::testing::patterned_frame;

// Generous: a loaded 2-core machine; these bound a failure, they time nothing.
constexpr std::chrono::milliseconds kMatchTimeout{60'000};
constexpr std::chrono::milliseconds kDeliveryTimeout{120'000};
constexpr std::uint32_t kStopFrame = 0xffffffffu;  // tests/camera_frame_node.cpp ends on it
constexpr std::size_t kMaxRgbBytes = 11'059'200;    // idl/device.idl's bound: 2560 x 1440 x 3

// Discovery signals nothing a reader could wait on: poll, bounded.
template <class Ready>
bool wait_matched(Ready ready) {
    const rig::WallStopwatch waited;
    while (!ready()) {
        if (waited.elapsed() > kMatchTimeout) return false;
        rig::pause_between_polls(std::chrono::milliseconds(5));
    }
    return true;
}

// Takes frames until `count` have arrived or the (generous) timeout passes.
std::vector<CameraFrame> take_frames(rig::Reader<CameraFrame>& reader, std::size_t count) {
    std::vector<CameraFrame> frames;
    const rig::WallStopwatch waited;
    while (frames.size() < count && waited.elapsed() < kDeliveryTimeout) {
        reader.wait_for_data(std::chrono::milliseconds(1000));
        for (CameraFrame& frame : reader.take_all()) frames.push_back(std::move(frame));
    }
    return frames;
}

// What went wrong with a frame, briefly (a failed EXPECT_EQ would print megabytes).
std::string describe(const CameraFrame& frame) {
    return "frame " + std::to_string(frame.frame_number()) + " " + std::to_string(frame.width_px()) + "x" +
           std::to_string(frame.height_px()) + ", " + std::to_string(frame.rgb().size()) + " bytes, " +
           (is_patterned(frame) ? "pattern intact" : "PATTERN BROKEN");
}

struct TwoParticipants {
    rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext camera{lease.domain_id(), "camera"};
    rig::DdsContext controller{lease.domain_id(), "controller"};
    rig::Writer<CameraFrame> writer{camera, rig::topics::kCameraLeftFrame};
    rig::Reader<CameraFrame> reader{controller, rig::topics::kCameraLeftFrame};
    TwoParticipants() {
        EXPECT_TRUE(wait_matched([&] { return writer.matched_readers() >= 1 && reader.matched_writers() >= 1; }));
    }
};

TEST(CameraFrameDds, FramesArriveBitIdenticalInOrderBetweenParticipants) {
    TwoParticipants dds;
    constexpr std::uint32_t kFrames = 8;
    // Written back to back, as a camera at 30 fps would outrun a slow reader:
    // keep-all keeps every one.
    for (std::uint32_t n = 0; n < kFrames; ++n) dds.writer.publish(patterned_frame(n, 1280, 720));
    ASSERT_TRUE(dds.writer.wait_delivered(kDeliveryTimeout));
    const std::vector<CameraFrame> frames = take_frames(dds.reader, kFrames);
    ASSERT_EQ(frames.size(), kFrames);
    for (std::uint32_t n = 0; n < kFrames; ++n) {
        EXPECT_EQ(frames[n].frame_number(), n);
        EXPECT_EQ(frames[n].rgb().size(), 1280u * 720u * 3u) << describe(frames[n]);
        EXPECT_TRUE(is_patterned(frames[n])) << describe(frames[n]);
    }
    EXPECT_FALSE(dds.reader.has_unread());
}

TEST(CameraFrameDds, EmptyAndLargestFramesAreDeliveredOnePastTheBoundIsRefused) {
    TwoParticipants dds;
    dds.writer.publish(patterned_frame(0, 0, 0));          // no pixels: a dead camera's driver may send it
    dds.writer.publish(patterned_frame(1, 2560, 1440));    // exactly the bound
    CameraFrame over = patterned_frame(2, 2560, 1440, kMaxRgbBytes + 1);
    try {
        dds.writer.publish(over);
        ADD_FAILURE() << "a frame one byte past the type's bound was written";
    } catch (const std::runtime_error& error) {
        // Said in words a user can act on: which topic, how big, what bound.
        const std::string what = error.what();
        EXPECT_NE(what.find(rig::topics::kCameraLeftFrame), std::string::npos) << what;
        EXPECT_NE(what.find("past its type's bound"), std::string::npos) << what;
    }
    dds.writer.publish(patterned_frame(3, 1280, 720));     // the stream goes on after a refusal
    ASSERT_TRUE(dds.writer.wait_delivered(kDeliveryTimeout));
    const std::vector<CameraFrame> frames = take_frames(dds.reader, 3);
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_EQ(frames[0].frame_number(), 0u);
    EXPECT_TRUE(frames[0].rgb().empty()) << describe(frames[0]);
    EXPECT_EQ(frames[1].frame_number(), 1u);
    EXPECT_EQ(frames[1].rgb().size(), kMaxRgbBytes) << describe(frames[1]);
    EXPECT_TRUE(is_patterned(frames[1])) << describe(frames[1]);
    EXPECT_EQ(frames[2].frame_number(), 3u);
    EXPECT_TRUE(is_patterned(frames[2])) << describe(frames[2]);
    EXPECT_EQ(dds.writer.written_count(), 3u);  // the refused frame was never counted as written
}

// The far side in its own process (tests/camera_frame_node.cpp) echoes every
// left frame back on the right topic: each frame crosses the process boundary
// twice, as RTPS fragments through the transports.
TEST(CameraFrameDds, FramesCrossTwoProcessesBitIdenticalInOrder) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext dds(lease.domain_id(), "camera");
    rig::Writer<CameraFrame> out(dds, rig::topics::kCameraLeftFrame);
    rig::Reader<CameraFrame> back(dds, rig::topics::kCameraRightFrame);
    // The echo's log in a folder of its own (GoogleTest's temp dir need not exist yet).
    const std::filesystem::path logs =
        std::filesystem::path(::testing::TempDir()) / ("camera-frame-dds-" + std::to_string(::getpid()));
    std::filesystem::create_directories(logs);
    rig::ChildProcess echo({RIG_CAMERA_FRAME_NODE, "--domain", std::to_string(lease.domain_id()), "--echo"},
                           (logs / "echo.log").string());
    ASSERT_TRUE(wait_matched([&] { return out.matched_readers() >= 1 && back.matched_writers() >= 1; }))
        << echo.exit_description().value_or("echo still running");

    std::vector<CameraFrame> sent;
    for (std::uint32_t n = 0; n < 6; ++n) sent.push_back(patterned_frame(n, 1280, 720));
    sent.push_back(patterned_frame(6, 0, 0));
    sent.push_back(patterned_frame(7, 2560, 1440));
    for (const CameraFrame& frame : sent) out.publish(frame);
    ASSERT_TRUE(out.wait_delivered(kDeliveryTimeout));
    const std::vector<CameraFrame> frames = take_frames(back, sent.size());
    ASSERT_EQ(frames.size(), sent.size()) << echo.exit_description().value_or("echo still running");
    for (std::size_t i = 0; i < sent.size(); ++i) {
        EXPECT_EQ(frames[i].frame_number(), sent[i].frame_number());
        EXPECT_TRUE(frames[i] == sent[i]) << describe(frames[i]);
    }
    out.publish(patterned_frame(kStopFrame, 0, 0));
    ASSERT_TRUE(out.wait_delivered(kDeliveryTimeout));
    EXPECT_EQ(echo.stop(std::chrono::milliseconds(30'000)), "process exited with status 0");
}

}  // namespace
