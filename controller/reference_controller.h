#pragma once
// The reference controller under test: what an STM32 board running the paper's
// firmware does, as a rig node. It reads only device topics (NMEA text, encoder
// count, button level), converts them itself (Eq. 3-6), and publishes its status
// and breakpoint events. It never sees truth.
//
// Subscriptions: device/gnss/nmea, device/wheel_encoder/count,
//                device/breakpoint_button/level
// Publications:  controller/status, controller/breakpoint_event
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "controller/breakpoint_locator.h"
#include "controller/breakpoint_store.h"
#include "controller/controller_config.h"
#include "controller/nmea_parser.h"
#include "rig/dds_context.h"
#include "rig/node.h"

namespace rig::controller {

class ReferenceController final : public Node {
public:
    ReferenceController(std::string node_name, ControllerConfig config, const std::filesystem::path& state_dir);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    void activate(TimeNs now_ns) override;
    TimeNs step(TimeNs now_ns) override;
    bool has_unread_input() const override;

private:
    void handle_sentence(const std::string& line, TimeNs now_ns);
    void handle_encoder(std::uint32_t count, TimeNs now_ns);
    void handle_button(bool pressed, TimeNs now_ns);
    void store_breakpoint_here(TimeNs now_ns);
    void on_breakpoint_reached(TimeNs now_ns);
    void select_target();
    void publish_event(msg::BreakpointEventKind kind, const StoredBreakpoint& breakpoint, TimeNs now_ns);
    void publish_status(TimeNs now_ns);
    double speed_m_s() const;

    // --- subscriptions
    std::unique_ptr<Reader<msg::NmeaSentence>> nmea_reader_;
    std::unique_ptr<Reader<msg::EncoderCount>> encoder_reader_;
    std::unique_ptr<Reader<msg::ButtonLevel>> button_reader_;
    // --- publications
    std::unique_ptr<Writer<msg::ControllerStatus>> status_writer_;
    std::unique_ptr<Writer<msg::BreakpointEvent>> event_writer_;

    std::string name_;
    ControllerConfig config_;
    BreakpointStore store_;
    BreakpointLocator locator_;

    // Latest GNSS state, assembled from GGA (position, quality) and RMC (course).
    std::optional<FixInput> last_fix_;
    std::optional<double> last_course_deg_;  // kept while standing (RMC course is empty then)
    int last_quality_ = 0;
    std::uint32_t rejected_sentences_ = 0;

    // Encoder samples within the Eq. 5 speed window: (time, count).
    std::deque<std::pair<TimeNs, std::uint32_t>> encoder_window_;
    std::optional<std::uint32_t> latest_count_;
    bool button_pressed_ = false;

    TimeNs status_period_ns_;
    TimeNs next_status_ns_ = 0;
};

}  // namespace rig::controller
