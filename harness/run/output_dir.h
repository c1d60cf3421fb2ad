#pragma once
// `rig run --out DIR` checked before any case runs (issue 14, "Output"): a
// path through a regular file, /dev/null, a read-only or already full file
// system are found here, with a clean error and nothing run, instead of after
// the cases have run (when the run used to end in SIGABRT and its results were
// lost). A disk that fills during the run cannot be foreseen: `rig run` then
// says which file could not be written and exits kExitResultsNotWritten.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace rig::harness {

// `rig run`'s exit status when the cases ran but results.json / junit.xml /
// report.txt could not be written (a full disk, the directory gone): distinct
// from 0 (all passed), 1 (a case failed), 2 (nothing run: bad input), 3 (a
// real-time case invalid: the rig overloaded) and 128 + N (stopped by signal
// N), so that no script takes the run for judged.
inline constexpr int kExitResultsNotWritten = 4;

// What is wrong with an output directory. what(): "--out PATH: PROBLEM".
class OutputDirError : public std::runtime_error {
public:
    OutputDirError(const std::filesystem::path& path, const std::string& problem)
        : std::runtime_error("--out " + path.string() + ": " + problem) {}
};

// Creates `out_dir` (and its parents) if missing, then proves that files can
// be created and written in it and in its cases/ by writing and removing a
// small probe file (kOutputProbeBytes) in each. Throws OutputDirError naming
// the path and the reason (not a directory and what it is instead, read-only
// file system, no space left, permission denied). Leaves whatever else is in
// the directory untouched.
void prepare_output_directory(const std::filesystem::path& out_dir);

// The probe's size: a file system without room for this much cannot hold a
// single trace (an empty trace database alone takes 4 KiB, plus its log).
inline constexpr std::size_t kOutputProbeBytes = 64 * 1024;

// After results could not be written: removes results.json and junit.xml of an
// earlier run from `out_dir` (removing needs no space), so that nothing reads
// them as this run's. Returns the names removed.
std::vector<std::string> remove_stale_results(const std::filesystem::path& out_dir);

}  // namespace rig::harness
