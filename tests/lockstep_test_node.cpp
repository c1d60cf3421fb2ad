// A minimal remote node for tests/lockstep_test.cpp: echoes every sentence it
// reads on "test/ping" to "test/pong" with a counter, wakes every --period-ms,
// and with --stall-at-ms stops answering ticks from that simulated time on, to
// prove the master fails such a node by name in bounded wall time.
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>

#include "rig/runtime/dds_context.h"
#include "rig/runtime/follower.h"

namespace {

class EchoNode final : public rig::Node {
public:
    EchoNode(std::string name, rig::TimeNs period_ns, rig::TimeNs stall_at_ns)
        : name_(std::move(name)), period_ns_(period_ns), stall_at_ns_(stall_at_ns) {}
    const std::string& name() const override { return name_; }
    void configure(rig::DdsContext& dds) override {
        ping_ = std::make_unique<rig::Reader<rig::msg::NmeaSentence>>(dds, "test/ping");
        pong_ = std::make_unique<rig::Writer<rig::msg::NmeaSentence>>(dds, "test/pong");
    }
    rig::TimeNs step(rig::TimeNs now_ns) override {
        if (now_ns >= stall_at_ns_) {
            for (;;) {  // stop answering: never returns, like a wedged firmware loop
                ping_->wait_for_data(std::chrono::milliseconds(1000));
            }
        }
        for (const auto& ping : ping_->take_all()) {
            rig::msg::NmeaSentence pong;
            pong.sentence(ping.sentence().to_string() + " #" + std::to_string(++count_) + " @" + std::to_string(now_ns));
            pong_->publish(pong);
        }
        return rig::next_period_boundary(now_ns, period_ns_);
    }

private:
    std::string name_;
    rig::TimeNs period_ns_;
    rig::TimeNs stall_at_ns_;
    int count_ = 0;
    std::unique_ptr<rig::Reader<rig::msg::NmeaSentence>> ping_;
    std::unique_ptr<rig::Writer<rig::msg::NmeaSentence>> pong_;
};

}  // namespace

int main(int argc, char** argv) {
    std::uint32_t domain = 0;
    std::string name = "echo";
    rig::TimeNs period_ns = 100'000'000;
    rig::TimeNs stall_at_ns = rig::kNever;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i];
        const std::string value = argv[i + 1];
        if (key == "--domain") domain = static_cast<std::uint32_t>(std::stoul(value));
        else if (key == "--node-name") name = value;
        else if (key == "--period-ms") period_ns = std::stoll(value) * 1'000'000;
        else if (key == "--stall-at-ms") stall_at_ns = std::stoll(value) * 1'000'000;
    }
    // The start-up a controller process makes (rig/runtime/follower.h), so the
    // lockstep tests run it too.
    rig::FollowerStartup startup;
    startup.domain_id = domain;
    startup.options.node_name = name;
    startup.options.idle_timeout = std::chrono::milliseconds(20'000);
    return rig::run_follower(startup, [&] { return std::make_unique<EchoNode>(name, period_ns, stall_at_ns); });
}
