#include "harness/regression/bencher_format.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "harness/report/sweep.h"

namespace rig::harness {

nlohmann::json bencher_metric_format(const RunSamples& samples) {
    nlohmann::json benchmarks = nlohmann::json::object();
    for (const CaseSamples& one : samples.cases) {
        std::set<std::string> metrics;
        for (const RunSample& run : one.runs) {
            for (const auto& [metric, value] : run.metrics) metrics.insert(metric);
        }
        nlohmann::json measures = nlohmann::json::object();
        for (const std::string& metric : metrics) {
            std::vector<double> values;
            for (const RunSample& run : one.runs) {
                const auto found = run.metrics.find(metric);
                if (found != run.metrics.end() && std::isfinite(found->second)) values.push_back(found->second);
            }
            if (values.empty()) continue;
            std::sort(values.begin(), values.end());
            nlohmann::json measure = {{"value", percentile_of_sorted(values, 50.0)}};
            if (values.size() > 1) {
                measure["lower_value"] = values.front();
                measure["upper_value"] = values.back();
            }
            measures[metric] = std::move(measure);
        }
        if (!measures.empty()) benchmarks[one.name] = std::move(measures);
    }
    return benchmarks;
}

}  // namespace rig::harness
