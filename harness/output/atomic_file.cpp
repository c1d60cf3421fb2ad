#include "harness/output/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace rig::harness {

void write_file_atomically(const std::filesystem::path& path, const std::string& content) {
    // The temporary lives beside the target (same file system, so rename is
    // atomic) and carries the pid so concurrent runs never share one.
    std::filesystem::path temporary = path;
    temporary.replace_filename("." + path.filename().string() + ".tmp-" + std::to_string(::getpid()));
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out) {
            throw std::runtime_error("cannot create " + temporary.string() + ": " + std::strerror(errno));
        }
        out.write(content.data(), static_cast<std::streamsize>(content.size()));
        out.flush();
        if (!out) {
            const std::string reason = std::strerror(errno);
            std::error_code ignored;
            std::filesystem::remove(temporary, ignored);
            throw std::runtime_error("cannot write " + temporary.string() + ": " + reason);
        }
    }
    std::error_code rename_error;
    std::filesystem::rename(temporary, path, rename_error);
    if (rename_error) {
        std::error_code ignored;
        std::filesystem::remove(temporary, ignored);
        throw std::filesystem::filesystem_error("cannot move results into place", temporary, path, rename_error);
    }
}

}  // namespace rig::harness
