// libFuzzer harness: the breakpoint-store loader (controller/breakpoint_store.h)
// on any file contents, and once in a while through a real file in a scratch
// state directory (load() as the controller runs it, with a corrupt file moved
// aside).
// Oracles beyond the sanitizers: a store that loads holds only valid positions,
// courses in [0, 360), distinct ids below next_id; written back it reads back
// the same and byte for byte the same text (the format is canonical).
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <string_view>

#include "controller/breakpoint_store.h"

namespace {

using namespace rig::controller;

void require(bool condition) {
    if (!condition) std::abort();  // a finding: libFuzzer keeps the input
}

void check(const StoreText& store) {
    std::set<std::uint32_t> ids;
    for (const StoredBreakpoint& breakpoint : store.breakpoints) {
        require(breakpoint.id >= 1 && breakpoint.id < store.next_id);
        require(ids.insert(breakpoint.id).second);
        require(std::isfinite(breakpoint.lat_deg) && std::abs(breakpoint.lat_deg) <= 90.0);
        require(std::isfinite(breakpoint.lon_deg) && std::abs(breakpoint.lon_deg) <= 180.0);
        require(breakpoint.course_deg >= 0.0 && breakpoint.course_deg < 360.0);
    }
}

// Through a real file now and then: the file layer (open, size, move aside).
void load_through_a_file(std::string_view text, bool parses) {
    static const std::filesystem::path directory = [] {
        std::string pattern = (std::filesystem::temp_directory_path() / "breakpoint_store_fuzz.XXXXXX").string();
        require(::mkdtemp(pattern.data()) != nullptr);
        return std::filesystem::path(pattern);
    }();
    std::filesystem::remove_all(directory);
    std::filesystem::create_directories(directory);
    const std::filesystem::path file = directory / "breakpoints.txt";
    std::ofstream(file, std::ios::binary) << text;
    BreakpointStore store(file);
    try {
        store.load();
        require(parses);
    } catch (const BreakpointStoreError& error) {
        require(!parses);
        require(error.kept_as() == std::filesystem::path(file.string() + ".corrupt-1"));
        require(std::filesystem::exists(error.kept_as()) && !std::filesystem::exists(file));
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    bool parses = false;
    try {
        const StoreText store = parse_store_text(text);
        parses = true;
        check(store);
        const std::string written = format_store_text(store);
        const StoreText again = parse_store_text(written);
        require(again.breakpoints == store.breakpoints && again.next_id == store.next_id);
        require(format_store_text(again) == written);
    } catch (const BreakpointStoreError& error) {
        require(error.line() >= 1 && !error.problem().empty());
    }
    if (size % 16 == 0) load_through_a_file(text, parses);
    return 0;
}
