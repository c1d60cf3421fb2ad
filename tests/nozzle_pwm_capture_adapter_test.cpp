// Seed 001 on the bench, the rig's side: NozzlePwmCaptureAdapter turns the HID
// I/O board's captured PWM (here the fake board's, on its own clock) into
// actuator/nozzle_pwm/duty, the topic the plant takes from a DDS controller.
// A DDS test (a leased domain, the loopback profile): labelled `dds`.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <optional>
#include <vector>

#include "idl/msg_traits.h"
#include "idl/topics.h"
#include "rig/host/domain_lease.h"
#include "rig/runtime/dds_context.h"
#include "rig/wire/hid_board.h"
#include "rig/wire/wire_adapters.h"
#include "tests/fake_hid_board.h"

namespace rig {
namespace {

TEST(NozzlePwmCaptureAdapter, PublishesTheCapturedDutiesAsTheDdsControllerWould) {
    DomainLease lease = DomainLease::acquire();
    DdsContext dds{lease.domain_id(), "nozzle_pwm_capture_test"};
    auto transport = std::make_unique<testing::FakeHidBoard>();
    testing::FakeHidBoard* fake = transport.get();
    HidBoard board(std::move(transport));
    NozzlePwmCaptureAdapter adapter(board, 6, 50.0);
    adapter.configure(dds);
    Reader<msg::NozzlePwm> reader(dds, topics::kNozzlePwm);
    // Matched before anything is published (the topic keeps no history for late readers).
    for (int wait = 0; wait < 1000 && reader.matched_writers() < 1; ++wait) reader.wait_for_data(std::chrono::milliseconds(10));
    ASSERT_GE(reader.matched_writers(), 1) << "the reader never matched the adapter's writer";

    // Seed 001's levels: 0, 40 and 100 % (Eq. 14), each nozzle its own phase.
    const std::vector<double> duty{40.0, 100.0, 0.0, 40.0, 100.0, 40.0};
    TimeNs now_ns = 0;
    now_ns = adapter.step(now_ns);  // enables capture
    for (int i = 0; i < 6; ++i) fake->set_pwm_source(i, {9.0, duty[static_cast<std::size_t>(i)], 9'000.0 * i});
    while (now_ns < seconds_to_ns(1.0)) {
        fake->advance_us(20'000);
        now_ns = adapter.step(now_ns);
    }
    ASSERT_GE(adapter.published(), 1u);
    // The newest sample the reader holds once the publications have arrived.
    std::optional<msg::NozzlePwm> latest;
    for (int wait = 0; wait < 100 && reader.received_count() < adapter.published(); ++wait) {
        reader.wait_for_data(std::chrono::milliseconds(100));
        for (const msg::NozzlePwm& pwm : reader.take_all()) latest = pwm;
    }
    for (const msg::NozzlePwm& pwm : reader.take_all()) latest = pwm;
    ASSERT_TRUE(latest) << "nothing arrived on " << topics::kNozzlePwm;
    EXPECT_NEAR(latest->frequency_hz(), 9.0, 1e-4);
    ASSERT_EQ(latest->duty_pct().size(), 6u);
    for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(latest->duty_pct()[i], duty[i], 0.002) << "nozzle " << i;
}

TEST(NozzlePwmCaptureAdapter, BadSettingsAreRefused) {
    auto transport = std::make_unique<testing::FakeHidBoard>();
    HidBoard board(std::move(transport));
    EXPECT_THROW(NozzlePwmCaptureAdapter(board, 7, 50.0), std::invalid_argument);
    EXPECT_THROW(NozzlePwmCaptureAdapter(board, 6, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace rig
