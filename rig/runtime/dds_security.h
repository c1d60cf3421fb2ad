#pragma once
// DDS-Security for the project's participants (docs/dds-security.md): Fast
// DDS's own plugins, PKI-DH authentication, Access-Permissions (governance and
// permissions signed by the run's CA) and AES-GCM-GMAC, layered onto the
// loopback profile (the transports and discovery stay exactly as the profile
// says). An identity is one directory holding the five files below; `rig run
// --dds-security` makes one for the rig and one for the controller per run,
// under OUT/security/.
//
// Which identity a participant gets: the one chosen with
// use_dds_security_identity() in this process, else the directory named by the
// environment variable RIG_DDS_SECURITY_DIR (how the rig hands the controller
// process its identity: a controller linking rig::node needs no code for it),
// else none (a plain participant, as before).
#include <filesystem>
#include <optional>
#include <string>

namespace eprosima::fastrtps::rtps {
class PropertyPolicy;
}

namespace rig {

inline constexpr const char* kDdsSecurityDirEnv = "RIG_DDS_SECURITY_DIR";

// The files of an identity directory. The CA certificate is both the identity
// CA (it signed every participant's certificate) and the permissions CA (it
// signed the governance and every permissions document).
inline constexpr const char* kSecurityCaFile = "ca.pem";
inline constexpr const char* kSecurityCertificateFile = "cert.pem";
inline constexpr const char* kSecurityPrivateKeyFile = "key.pem";        // mode 0600
inline constexpr const char* kSecurityGovernanceFile = "governance.p7s";  // S/MIME, signed by the CA
inline constexpr const char* kSecurityPermissionsFile = "permissions.p7s";

// Participants this process creates from now on authenticate with the identity
// in `identity_dir` (an empty path: none); std::nullopt goes back to the
// environment's choice. Participants already created keep what they have.
void use_dds_security_identity(std::optional<std::filesystem::path> identity_dir);

// The identity directory the next participant gets (empty: none).
std::filesystem::path dds_security_identity();

// Adds the security plugins' properties for `identity_dir` to `properties`.
// Throws std::runtime_error naming the identity directory and the file that is
// missing or unreadable, so a bad directory is told before Fast DDS's own
// (vaguer) refusal.
void add_dds_security_properties(const std::filesystem::path& identity_dir,
                                 eprosima::fastrtps::rtps::PropertyPolicy& properties);

// Whether a participant's properties name the authentication plugin (it was
// created with an identity).
bool has_dds_security(const eprosima::fastrtps::rtps::PropertyPolicy& properties);

}  // namespace rig
