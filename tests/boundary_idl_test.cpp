// Seed 001's new topic types (idl/actuator.idl NozzlePwm, idl/device.idl
// SerialLine, idl/truth.idl Vehicle2dTruth / NozzlesTruth): each survives a
// CDR round trip through its generated PubSubType (no participant, no network).
// That every topic name is unique, the new ones included, topic_table_test
// checks over the whole topic table.
#include <gtest/gtest.h>

#include <fastdds/rtps/common/SerializedPayload.h>

#include <string>

#include "idl/msg_traits.h"

namespace {

template <class Msg>
Msg round_trip(Msg in) {
    typename rig::MsgTraits<Msg>::PubSubType type;
    eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&in)());
    EXPECT_TRUE(type.serialize(&in, &payload));
    Msg out;
    EXPECT_TRUE(type.deserialize(&payload, &out));
    return out;
}

TEST(BoundaryIdl, NozzlePwmRoundTrips) {
    rig::msg::NozzlePwm pwm;
    pwm.frequency_hz(9.0);
    pwm.duty_pct({0.0, 40.0, 40.0, 100.0, 100.0, 0.0});
    const rig::msg::NozzlePwm back = round_trip(pwm);
    EXPECT_EQ(back.frequency_hz(), 9.0);
    EXPECT_EQ(back.duty_pct(), pwm.duty_pct());
}

TEST(BoundaryIdl, LaserLineRoundTrips) {
    rig::msg::SerialLine line;
    line.text("D=0.503m\r\n");
    EXPECT_EQ(round_trip(line).text(), "D=0.503m\r\n");
}

TEST(BoundaryIdl, TruthRoundTrips) {
    rig::msg::Vehicle2dTruth v;
    v.time_ns(6'266'666'667);
    v.east_m(0.3);
    v.north_m(-2.6);
    v.heading_deg(359.5);
    v.boom_offset_m(1.0);
    v.antenna_lat_deg(35.1);
    const rig::msg::Vehicle2dTruth vb = round_trip(v);
    EXPECT_EQ(vb.time_ns(), 6'266'666'667);
    EXPECT_EQ(vb.north_m(), -2.6);
    EXPECT_EQ(vb.heading_deg(), 359.5);
    EXPECT_EQ(vb.antenna_lat_deg(), 35.1);

    rig::msg::NozzlesTruth n;
    n.time_ns(42);
    for (int i = 0; i < 6; ++i) {
        rig::msg::NozzleTruth t;
        t.east_m(-1.25 + 0.5 * i);
        t.duty_pct(i % 2 ? 40.0 : 100.0);
        t.opening(0.5);
        t.delivered_l(0.01 * i);
        n.nozzles().push_back(t);
    }
    const rig::msg::NozzlesTruth nb = round_trip(n);
    ASSERT_EQ(nb.nozzles().size(), 6u);
    EXPECT_EQ(nb.nozzles()[5].east_m(), 1.25);
    EXPECT_EQ(nb.nozzles()[1].duty_pct(), 40.0);
    EXPECT_EQ(nb.nozzles()[3].delivered_l(), 0.03);
}

}  // namespace
