#include "rig/runtime/dds_security.h"

#include <cstdlib>
#include <fstream>
#include <mutex>
#include <stdexcept>

#include <fastdds/rtps/attributes/PropertyPolicy.h>

namespace rig {
namespace {

std::mutex choice_mutex;
// Set by use_dds_security_identity(); nullopt: the environment decides.
std::optional<std::filesystem::path> chosen_identity;

constexpr const char* kAuthPluginProperty = "dds.sec.auth.plugin";

}  // namespace

void use_dds_security_identity(std::optional<std::filesystem::path> identity_dir) {
    std::lock_guard lock(choice_mutex);
    chosen_identity = std::move(identity_dir);
}

std::filesystem::path dds_security_identity() {
    {
        std::lock_guard lock(choice_mutex);
        if (chosen_identity) return *chosen_identity;
    }
    const char* from_environment = std::getenv(kDdsSecurityDirEnv);
    return from_environment != nullptr ? std::filesystem::path(from_environment) : std::filesystem::path();
}

void add_dds_security_properties(const std::filesystem::path& identity_dir,
                                 eprosima::fastrtps::rtps::PropertyPolicy& properties) {
    // Fast DDS takes the files as file:// URIs; an absolute path keeps them
    // valid whatever the participant's working directory.
    auto uri_of = [&](const char* file) {
        const std::filesystem::path path = std::filesystem::absolute(identity_dir / file);
        std::error_code error;
        if (!std::filesystem::is_regular_file(path, error)) {
            throw std::runtime_error("DDS-Security identity " + identity_dir.string() + ": " + path.string() +
                                     " is missing or not a regular file (" + kDdsSecurityDirEnv +
                                     " or rig run --dds-security names the directory; docs/dds-security.md)");
        }
        if (!std::ifstream(path)) {
            throw std::runtime_error("DDS-Security identity " + identity_dir.string() + ": cannot read " +
                                     path.string());
        }
        return "file://" + path.string();
    };
    auto& seq = properties.properties();
    seq.emplace_back(kAuthPluginProperty, "builtin.PKI-DH");
    seq.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", uri_of(kSecurityCaFile));
    seq.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", uri_of(kSecurityCertificateFile));
    seq.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", uri_of(kSecurityPrivateKeyFile));
    seq.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
    seq.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", uri_of(kSecurityCaFile));
    seq.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", uri_of(kSecurityGovernanceFile));
    seq.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", uri_of(kSecurityPermissionsFile));
    seq.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

bool has_dds_security(const eprosima::fastrtps::rtps::PropertyPolicy& properties) {
    for (const auto& property : properties.properties()) {
        if (property.name() == kAuthPluginProperty) return true;
    }
    return false;
}

}  // namespace rig
