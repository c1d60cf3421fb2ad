#include "harness/falsify/falsify_setup.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <stdexcept>

#include "harness/systems/systems.h"
#include "rig/config/file_access.h"
#include "rig/config/yaml_fields.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

bool whole_number_text(const std::string& text) {
    const std::size_t digits = !text.empty() && (text[0] == '-' || text[0] == '+') ? 1 : 0;
    return text.size() > digits && std::all_of(text.begin() + static_cast<std::ptrdiff_t>(digits), text.end(),
                                               [](char c) { return c >= '0' && c <= '9'; });
}

std::optional<double> number_of(const std::string& text) {
    const std::size_t skip = !text.empty() && text[0] == '+' ? 1 : 0;
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data() + skip, text.data() + text.size(), value);
    if (error != std::errc{} || end != text.data() + text.size() || !std::isfinite(value)) return std::nullopt;
    return value;
}

std::string vary_text(const VaryRange& range) { return "--vary " + range_text(range); }

// The case with the range at `value`, loaded and checked as a run checks it
// (the controller's section, the timeline), so that a bad end or choice is
// refused before anything runs, not found invalid point by point.
void check_case_at(const FalsifyRequest& request, const VaryRange& range, double value, const RunOptions& options) {
    validate_for_run(load_case_file(request.case_file, point_settings(request.settings, {range}, {value})), options);
}

// Where and how the base case (with its settings applied) writes each of the
// range's keys; a key it does not write is refused, naming the nearest it does.
std::vector<WrittenValue> written_keys(const VaryRange& range, const FalsifyRequest& request,
                                       const std::string& applied) {
    std::vector<WrittenValue> written;
    for (const std::string& key : range.keys) {
        try {
            written.push_back(written_value(applied, request.case_file.string(), key));
        } catch (const ConfigError& error) {
            throw std::invalid_argument(vary_text(range) + ": " + error.what());
        }
    }
    return written;
}

// A choice key's keys in the base case: each written (the first's value is
// the base), each choice a valid case: the loader refuses a word that is not
// one of the key's own choices, or a number outside its bounds.
void check_choices(VaryRange& range, const FalsifyRequest& request, const std::string& applied,
                   const RunOptions& options) {
    range.base_text = written_keys(range, request, applied).front().text;
    const auto listed = std::find(range.choices.begin(), range.choices.end(), range.base_text);
    range.base = listed == range.choices.end() ? -1.0 : static_cast<double>(listed - range.choices.begin());
    for (std::size_t choice = 0; choice < range.choices.size(); ++choice) {
        try {
            check_case_at(request, range, static_cast<double>(choice), options);
        } catch (const std::exception& error) {
            throw std::invalid_argument(vary_text(range) + ": at " + range.choices[choice] + ": " + error.what());
        }
    }
}

// The range's keys in the base case: each written as a number (the first's
// value is the base, and says whether the key is a whole number), each end of
// the range a valid case.
void check_range(VaryRange& range, const FalsifyRequest& request, const std::string& base_text,
                 const RunOptions& options) {
    const std::string file = request.case_file.string();
    const std::string applied = apply_key_settings(base_text, file, request.settings);
    if (range.is_choice()) {
        check_choices(range, request, applied, options);
        return;
    }
    const std::vector<WrittenValue> all_written = written_keys(range, request, applied);
    for (std::size_t index = 0; index < all_written.size(); ++index) {
        const WrittenValue& written = all_written[index];
        const std::optional<double> base = number_of(written.text);
        if (!base) {
            throw std::invalid_argument(vary_text(range) + ": " +
                                        ConfigError(written.where, "is '" + written.text +
                                                                       "', not a number: vary a word over its "
                                                                       "choices, " + range.key + "=A,B")
                                            .what());
        }
        if (index > 0) continue;
        range.base = *base;
        range.base_text = written.text;
        range.integer = whole_number_text(written.text);
    }
    if (range.integer && (range.low != std::floor(range.low) || range.high != std::floor(range.high))) {
        throw std::invalid_argument(vary_text(range) + ": " + range.keys.front() + " is a whole number in " + file +
                                    ": its range must be whole numbers too");
    }
    for (const double end : {range.low, range.high}) {
        try {
            check_case_at(request, range, end, options);
        } catch (const std::exception& error) {
            throw std::invalid_argument(vary_text(range) + ": at " + value_text(range, end) + ": " + error.what());
        }
    }
}

}  // namespace

FalsifyRequest read_search_file(const std::filesystem::path& path) {
    const YamlSection root = YamlSection::load_file(path);
    const YamlSection search = root.required_section("search");
    FalsifyRequest request;
    request.search_file = path;
    const std::string case_name = search.required<std::string>("case");
    request.case_file = (path.parent_path() / case_name).lexically_normal();
    const std::vector<std::string> vary = search.string_list("vary");
    if (search.has("vary") && vary.empty()) search.fail("vary", "no key to vary: give KEY=LO:HI or KEY=A,B items");
    for (std::size_t index = 0; index < vary.size(); ++index) {
        try {
            request.ranges.push_back(parse_vary(vary[index]));
        } catch (const std::invalid_argument& error) {
            throw ConfigError(search.item_location("vary", index), error.what());
        }
    }
    const std::vector<std::string> settings = search.string_list("set");
    for (std::size_t index = 0; index < settings.size(); ++index) {
        try {
            request.settings.push_back(parse_key_setting(settings[index]));
        } catch (const std::invalid_argument& error) {
            throw ConfigError(search.item_location("set", index), error.what());
        }
    }
    request.metrics = search.string_list("metrics");
    request.options.budget = static_cast<std::size_t>(
        search.optional_in_range<std::uint64_t>("budget", request.options.budget, Bounds::closed(1, 100000)));
    request.seeds = search.optional_in_range<std::uint64_t>("seeds", 0, Bounds::closed(0, 1000));
    const std::string method = search.optional_enum("method", {"crs2", "direct", "isres", "random"}, "crs2");
    request.options.method = search_method_named(method).value_or(SearchMethod::crs2);
    request.options.start_points =
        static_cast<std::size_t>(search.optional_in_range<std::uint64_t>("start", 0, Bounds::closed(0, 100000)));
    request.options.seed = search.optional<std::uint64_t>("search_seed", request.options.seed);
    request.options.stop_at_first = search.optional<bool>("first", false);
    root.finish();
    if (request.ranges.empty()) {
        throw ConfigError(search.location(), "vary: required: the keys to vary, KEY=LO:HI or KEY=A,B");
    }
    std::error_code error;
    if (!std::filesystem::is_regular_file(request.case_file, error)) {
        throw ConfigError(search.location("case"), "no case file " + request.case_file.string());
    }
    return request;
}

PreparedSearch prepare_search(const FalsifyRequest& request, const RunOptions& options) {
    if (request.ranges.empty()) throw std::invalid_argument("nothing to vary: give --vary KEY=LO:HI or KEY=A,B");
    PreparedSearch prepared;
    prepared.base = load_case_file(request.case_file, request.settings);
    prepared.base_text = read_regular_file(request.case_file, OpenOptions{.no_follow = false,
                                                                          .max_bytes = kMaxConfigFileBytes,
                                                                          .what = "case file"});
    validate_for_run(prepared.base, options);
    if (prepared.base.mode != ClockMode::lockstep) {
        throw std::invalid_argument(request.case_file.string() +
                                    ": a real-time case runs on the wall clock; a search runs lockstep cases");
    }
    FalsifyCase& search = prepared.search_case;
    search.file = request.case_file;
    search.settings = request.settings;
    search.ranges = request.ranges;
    for (std::size_t index = 0; index < search.ranges.size(); ++index) {
        for (std::size_t earlier = 0; earlier < index; ++earlier) {
            for (const std::string& key : search.ranges[index].keys) {
                const std::vector<std::string>& earlier_keys = search.ranges[earlier].keys;
                if (std::find(earlier_keys.begin(), earlier_keys.end(), key) != earlier_keys.end()) {
                    throw std::invalid_argument(vary_text(search.ranges[index]) + ": " + key + " is varied twice");
                }
            }
        }
        check_range(search.ranges[index], request, prepared.base_text, options);
    }
    check_choice_cells(search.ranges, request.options.budget);
    const std::map<std::string, double> limits = effective_limits(prepared.base);
    const std::vector<std::string> limited = limited_metrics(limits);
    search.metrics = request.metrics.empty() ? limited : request.metrics;
    for (const std::string& metric : search.metrics) {
        if (std::find(limited.begin(), limited.end(), metric) != limited.end()) continue;
        std::string known;
        for (const std::string& name : limited) known += (known.empty() ? "" : ", ") + name;
        throw std::invalid_argument("--metric " + metric + ": " + request.case_file.string() +
                                    " has no limit on it (its limited metrics: " + (known.empty() ? "none" : known) + ")");
    }
    if (search.metrics.empty()) {
        throw std::invalid_argument(request.case_file.string() + ": the case limits no metric, so no margin can be taken");
    }
    search.seeds = search_seeds(prepared.base, request.seeds);
    return prepared;
}

}  // namespace rig::harness
