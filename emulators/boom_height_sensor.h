#pragma once
// The pull-wire sensor on the boom's electric push rod (seed 000 sec. 2.2.3 and
// 2.3): it tells the board the four-bar linkage's height change h, from which the
// controller computes L4 (Eq. 6). Modelled as a linear potentiometer output:
// V = h / range_m x 3.3 V, published at a fixed rate.
#include <memory>
#include <string>

#include "emulators/plant.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/node.h"
#include "rig/papers/seed000.h"
#include "emulators/boom_height_sensor_params.h"

namespace rig::emulators {

class BoomHeightSensor final : public Node {
public:
    BoomHeightSensor(const Plant& plant, BoomHeightSensorParams params);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    double voltage_for(double linkage_rise_m) const;

private:
    std::string name_ = "boom_height_sensor";
    const Plant& plant_;
    BoomHeightSensorParams params_;
    TimeNs period_ns_;
    std::unique_ptr<Writer<msg::AnalogInput>> voltage_writer_;
};

}  // namespace rig::emulators
