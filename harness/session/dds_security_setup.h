#pragma once
// `rig run --dds-security` (docs/dds-security.md): the credentials of one run,
// made with the openssl command line under OUT/security/ before any case
// starts: a CA of its own, an identity for the rig and one for the controller
// (EC prime256v1 keys, certificates signed by the CA), the domain governance
// and each identity's permissions, derived from the topic table
// (idl/topics.json, compiled in) and signed by the CA as S/MIME. The CA's key
// is deleted once they are signed: nothing more can be signed for this run.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rig::harness {

// The identities a run has, by the names topics.json gives writers and readers.
inline constexpr const char* kRigIdentity = "rig";
inline constexpr const char* kControllerIdentity = "controller";

struct DdsSecurityRun {
    std::filesystem::path dir;  // OUT/security
    // An identity's directory (rig/runtime/dds_security.h: ca.pem, cert.pem, key.pem, governance.p7s, permissions.p7s).
    std::filesystem::path identity_dir(const std::string& identity) const { return dir / identity; }
};

// Makes the run's credentials in `dir` (its former content is removed; the
// directory and every key are readable by this user only). `openssl` is the
// program run (from PATH when it has no '/'). Throws std::runtime_error naming
// the openssl command that failed, with its output.
DdsSecurityRun make_dds_security_run(const std::filesystem::path& dir, const std::string& openssl = "openssl");

// What a process started with this identity is given: RIG_DDS_SECURITY_DIR set
// to its directory (rig/runtime/dds_security.h); set empty (no identity)
// without a run's credentials.
std::vector<std::string> dds_security_environment(const std::optional<std::filesystem::path>& run_dir,
                                                  const std::string& identity);

// Who may publish and subscribe what, as the permissions documents say it.
struct TopicGrant {
    std::vector<std::string> publish;            // topics of the table this identity writes
    std::vector<std::string> subscribe;          // topics of the table it reads ("*": every topic)
    std::vector<std::string> denied_publish;     // the table's other topics
    std::vector<std::string> denied_subscribe;
    std::vector<std::string> open_publish;       // patterns allowed after the denials (the controller's own topics)
};
// From the topic table: throws std::runtime_error for an identity it does not name.
TopicGrant topic_grant(const std::string& identity);

// The documents before signing (what the .p7s files carry as clear text).
std::string governance_xml();
// `not_before` / `not_after`: "YYYY-MM-DDTHH:MM:SS", as the permissions schema writes times.
std::string permissions_xml(const std::string& identity, const std::string& subject_rfc2253,
                            const std::string& not_before, const std::string& not_after);

}  // namespace rig::harness
