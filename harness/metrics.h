#pragma once
// Metrics computed from truth (DESIGN.md "What the harness measures"). Only the
// harness computes metrics; the controller never sees truth.
#include <map>
#include <string>

#include "emulators/plant.h"
#include "harness/trace_recorder.h"

namespace rig::harness {

// Breakpoint identification (seed 000 sec. 2.5.1, Tables 3-4):
//   breakpoint_error_m         |nozzle line - true breakpoint| when the controller
//                              declares "reached" (the paper's distance from the mark)
//   breakpoint_error_signed_m  + = declared after the nozzle line passed it
//   breakpoint_store_error_m   how far the stored breakpoint lies from the true one
//   breakpoint_reached_count   number of "reached" events (1 expected)
// A metric the run could not produce (no "reached" event) is absent: the judge
// then reports it as missing, which fails a limit on it.
std::map<std::string, double> breakpoint_metrics(const TraceRecorder& trace, const emulators::Plant& plant,
                                                 double breakpoint_along_m);

}  // namespace rig::harness
