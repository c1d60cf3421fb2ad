#pragma once
// One subcommand of `rig` (harness/commands/main.cpp holds the table of them):
// its options are declared on the command line when it is made, and it runs
// when the command line named it. Each lives beside what it runs.
namespace CLI {
class App;
}

namespace rig::harness {

class Subcommand {
public:
    virtual ~Subcommand() = default;
    // Whether the command line named this subcommand.
    virtual bool parsed() const = 0;
    // Runs it: the exit status (0 done, 1 failed, 2 a usage error; some have more, said in their --help).
    virtual int run() = 0;
    // Whether this process takes its DDS-Security identity from the
    // environment (RIG_DDS_SECURITY_DIR) as a controller does: only the
    // bench's second process. Otherwise the rig's participants hold none
    // unless a run asks for one (`rig run --dds-security`).
    virtual bool security_from_environment() const { return false; }
};

}  // namespace rig::harness
