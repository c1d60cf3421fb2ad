#pragma once
// The pump-outlet flow sensor (seed 000 sec. 2.4.2, Eq. 8): a 4-20 mA transmitter
// over 0..full_scale_m3_h, through a current-to-voltage module to 0-3.3 V at an
// ADC pin of the board. Publishes the pin voltage at a fixed rate.
//
//   I = 4 mA + 16 mA x Q / Q_F          (saturates at 20 mA above full scale)
//   V = (I - 4 mA) / 16 mA x 3.3 V       (the module maps the 16 mA span onto u = 3.3 V)
//
// The controller inverts it with Eq. 8. Faults: noise_mv (ADC and wiring noise,
// Gaussian, seeded), offset_ma (a transmitter zero error).
#include <cstdint>
#include <memory>
#include <string>

#include "emulators/seeded_random.h"
#include "emulators/spray_circuit.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/node.h"
#include "rig/papers/seed000.h"
#include "emulators/pump_flow_sensor_params.h"

namespace rig::emulators {

class PumpFlowSensor final : public Node {
public:
    PumpFlowSensor(const SprayCircuit& circuit, PumpFlowSensorParams params);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    // The pin voltage for a pump flow, without noise (the transfer function above).
    double voltage_for(double pump_flow_l_min) const;

private:
    std::string name_ = "pump_flow_sensor";
    const SprayCircuit& circuit_;
    PumpFlowSensorParams params_;
    SeededRandom noise_;
    TimeNs period_ns_;
    std::unique_ptr<Writer<msg::AnalogInput>> voltage_writer_;
};

}  // namespace rig::emulators
