#pragma once
// Checks on command-line values that CLI11's own conversion lets through.
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdlib>
#include <string>

namespace rig::harness {

// An unsigned 64-bit integer written in decimal digits only: CLI11 converts
// "-1" to 2^64 - 1 and a number past 2^64 - 1 to something else, unsaid.
inline CLI::Validator unsigned_decimal_check() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) {
                return "must be a non-negative integer in decimal digits, got '" + text + "'";
            }
            errno = 0;
            (void)std::strtoull(text.c_str(), nullptr, 10);
            if (errno == ERANGE) return "must be at most 18446744073709551615, got " + text;
            return {};
        },
        "UINT64");
}

}  // namespace rig::harness
