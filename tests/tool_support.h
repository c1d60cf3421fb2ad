#pragma once
// The programs the tests run besides the rig's own (gnuplot, xmllint, gpsd,
// node, ...). scripts/setup installs every one of them (scripts/debian-packages.txt),
// so one that is missing is a broken set-up: the test that needs it fails,
// naming the program and the package that provides it. It does not skip, since
// a skip reads as a pass wherever the suite's result is summed up.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

namespace rig::testing {

// Where `program` is: the first executable of that name on PATH or in the sbin
// folders (gpsd is in /usr/sbin, which a user's PATH may not have); "" if none.
inline std::string installed_program(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::istringstream folders(std::string(path == nullptr ? "" : path) + ":/usr/local/sbin:/usr/sbin:/sbin");
    for (std::string folder; std::getline(folders, folder, ':');) {
        if (folder.empty()) continue;
        const std::filesystem::path candidate = std::filesystem::path(folder) / program;
        std::error_code error;
        if (std::filesystem::is_regular_file(candidate, error) && ::access(candidate.c_str(), X_OK) == 0) {
            return candidate.string();
        }
    }
    return "";
}

// ASSERT_TRUE(tool_installed("xmllint", "libxml2-utils")): fails naming the program
// and its Debian package when the program is not installed.
inline ::testing::AssertionResult tool_installed(const std::string& program, const std::string& package) {
    if (!installed_program(program).empty()) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << program << " is not installed: it comes in the Debian package " << package
                                         << ", which scripts/setup installs";
}

}  // namespace rig::testing
