#include "harness/run/output_dir.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "rig/config/file_access.h"

namespace rig::harness {

namespace {

std::string errno_text(int error_number) { return std::strerror(error_number); }

// `dir` exists (following symlinks, as the user may point --out at a link to
// the real place) and is a directory.
void require_directory(const std::filesystem::path& shown, const std::filesystem::path& dir) {
    struct stat status {};
    if (::stat(dir.c_str(), &status) != 0) {
        throw OutputDirError(shown, dir.string() + ": " + errno_text(errno));
    }
    if (!S_ISDIR(status.st_mode)) {
        throw OutputDirError(shown, dir.string() + " is " + describe_file_type(status.st_mode) +
                                        ", expected a directory (or a path where one can be made)");
    }
}

// Writes kOutputProbeBytes into a new file in `dir`, syncs and removes it.
void probe_writable(const std::filesystem::path& shown, const std::filesystem::path& dir) {
    const std::filesystem::path probe = dir / (".rig-write-probe-" + std::to_string(::getpid()));
    FileDescriptor fd(::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600));
    if (fd.get() < 0) {
        throw OutputDirError(shown, "cannot create files in " + dir.string() + ": " + errno_text(errno));
    }
    const std::vector<char> block(kOutputProbeBytes, '\0');
    int write_error = 0;
    std::size_t written = 0;
    while (written < block.size() && write_error == 0) {
        const ssize_t n = ::write(fd.get(), block.data() + written, block.size() - written);
        if (n < 0 && errno != EINTR) write_error = errno;
        if (n > 0) written += static_cast<std::size_t>(n);
    }
    // fsync: a file system that delays allocation reports no space only here.
    if (write_error == 0 && ::fsync(fd.get()) != 0) write_error = errno;
    if (fd.close_now() != 0 && write_error == 0) write_error = errno;
    ::unlink(probe.c_str());
    if (write_error != 0) {
        throw OutputDirError(shown, "cannot write " + std::to_string(kOutputProbeBytes / 1024) + " KiB in " +
                                        dir.string() + ": " + errno_text(write_error));
    }
}

}  // namespace

void prepare_output_directory(const std::filesystem::path& out_dir) {
    // Parents first, one by one, so the message names the component that is in the way.
    std::filesystem::path walked;
    for (const std::filesystem::path& part : out_dir) {
        walked /= part;
        if (walked.empty() || walked == walked.root_path()) continue;
        struct stat status {};
        if (::stat(walked.c_str(), &status) == 0) {
            require_directory(out_dir, walked);
            continue;
        }
        if (errno != ENOENT) throw OutputDirError(out_dir, walked.string() + ": " + errno_text(errno));
        if (::mkdir(walked.c_str(), 0777) != 0 && errno != EEXIST) {
            throw OutputDirError(out_dir, "cannot create " + walked.string() + ": " + errno_text(errno));
        }
        require_directory(out_dir, walked);
    }
    probe_writable(out_dir, out_dir);
    // cases/ holds every case's directory: it must be a directory we can write in too.
    const std::filesystem::path cases = out_dir / "cases";
    if (::mkdir(cases.c_str(), 0777) != 0 && errno != EEXIST) {
        throw OutputDirError(out_dir, "cannot create " + cases.string() + ": " + errno_text(errno));
    }
    require_directory(out_dir, cases);
    probe_writable(out_dir, cases);
}

std::vector<std::string> remove_stale_results(const std::filesystem::path& out_dir) {
    std::vector<std::string> removed;
    for (const char* name : {"results.json", "junit.xml", "report.txt"}) {
        if (::unlink((out_dir / name).c_str()) == 0) removed.emplace_back(name);
    }
    return removed;
}

}  // namespace rig::harness
