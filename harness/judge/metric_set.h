#pragma once
// A judge's metrics: values, and the limited ones the run gave no value for
// with why (docs/metrics.md). Every system's judge returns one.
#include <map>
#include <string>

namespace rig::harness {

struct MetricSet {
    std::map<std::string, double> values;
    // Metric -> why the run gave no value for it ("never settled: ...").
    std::map<std::string, std::string> not_measured;
    // Adds `other`'s metrics; a name in both takes other's value or reason.
    void merge(const MetricSet& other) {
        for (const auto& [name, value] : other.values) {
            values[name] = value;
            not_measured.erase(name);
        }
        for (const auto& [name, why] : other.not_measured) {
            if (!values.count(name)) not_measured[name] = why;
        }
    }
};

}  // namespace rig::harness
