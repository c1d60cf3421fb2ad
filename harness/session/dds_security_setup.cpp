#include "harness/session/dds_security_setup.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "rig/host/child_process.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_security.h"

namespace rig::harness {

extern const char* const kTopicTableJson;  // generated from idl/topics.json

namespace {

// Certificates and permissions are valid from a day before the run (another
// host's clock may be behind this one's; Fast DDS reads the permissions' times
// as local time) to a week after it: longer than any run, short enough that a
// copied identity does not stay good. Wall-clock times, never in a trace.
constexpr int kValidDaysAfter = 7;
constexpr int kValidDaysBefore = 1;
// An openssl command is quick; this bound only keeps a wedged one from hanging the run.
constexpr auto kOpensslBound = std::chrono::seconds(60);
// Every DDS domain a case may use (rig/host/domain_lease.cpp: the well-known ports end at 232).
constexpr int kLastDomain = 232;
// The subjects' organisation: identities are told apart by their common name.
constexpr const char* kOrganisation = "sprayer-hil-rig";

std::string subject_rfc2253(const std::string& common_name) {
    return "CN=" + common_name + ",O=" + kOrganisation;
}

const nlohmann::json& topic_table() {
    static const nlohmann::json table = nlohmann::json::parse(kTopicTableJson).at("topics");
    return table;
}

std::string xml_escape(const std::string& text) {
    std::string escaped;
    for (const char c : text) {
        switch (c) {
            case '&': escaped += "&amp;"; break;
            case '<': escaped += "&lt;"; break;
            case '>': escaped += "&gt;"; break;
            default: escaped += c;
        }
    }
    return escaped;
}

std::string topics_element(const std::vector<std::string>& topics, const char* indent) {
    std::string xml = std::string(indent) + "<topics>\n";
    for (const std::string& topic : topics) xml += std::string(indent) + "  <topic>" + xml_escape(topic) + "</topic>\n";
    return xml + indent + "</topics>\n";
}

// Runs one openssl command to its end; its output goes to the run's openssl.log.
class Openssl {
public:
    Openssl(std::string program, std::filesystem::path log) : program_(std::move(program)), log_(std::move(log)) {}

    void operator()(std::vector<std::string> args) {
        args.insert(args.begin(), program_);
        const std::filesystem::path output = log_.parent_path() / "openssl-last.log";
        std::string ended;
        std::string command_line;
        {
            ChildProcess process(args, output);
            command_line = process.command_line();
            ended = process.stop(std::chrono::duration_cast<std::chrono::milliseconds>(kOpensslBound));
        }
        std::ifstream in(output);
        std::stringstream text;
        text << in.rdbuf();
        std::filesystem::remove(output);
        std::ofstream(log_, std::ios::app) << "$ " << command_line << "\n" << text.str();
        if (ended != "process exited with status 0") {
            throw std::runtime_error("making the DDS-Security credentials: '" + command_line + "' " + ended + ": " +
                                     text.str());
        }
    }

private:
    std::string program_;
    std::filesystem::path log_;
};

// An empty file only this user can read, for openssl to write a key into
// (it keeps the mode of a file that exists): the key is never readable by others.
void create_private_file(const std::filesystem::path& path) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0) throw std::runtime_error("cannot create " + path.string() + " for a private key");
    ::close(fd);
}

void write_text(const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path);
    out << text;
    if (!out.flush()) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace

std::vector<std::string> dds_security_environment(const std::optional<std::filesystem::path>& run_dir,
                                                  const std::string& identity) {
    // Without credentials, the variable is set empty: one in the rig's own
    // environment must not give the controller an identity the rig does not share.
    if (!run_dir) return {std::string(kDdsSecurityDirEnv) + "="};
    return {std::string(kDdsSecurityDirEnv) + "=" + std::filesystem::absolute(*run_dir / identity).string()};
}

TopicGrant topic_grant(const std::string& identity) {
    if (identity != kRigIdentity && identity != kControllerIdentity) {
        throw std::runtime_error("no DDS-Security identity '" + identity + "' (the topic table names rig and controller)");
    }
    TopicGrant grant;
    for (const nlohmann::json& topic : topic_table()) {
        const std::string name = topic.at("name");
        const auto& readers = topic.at("readers");
        const bool writes = topic.at("writer") == identity;
        const bool reads = std::find(readers.begin(), readers.end(), identity) != readers.end();
        (writes ? grant.publish : grant.denied_publish).push_back(name);
        if (identity == kControllerIdentity) (reads ? grant.subscribe : grant.denied_subscribe).push_back(name);
    }
    if (identity == kRigIdentity) {
        // The rig records every topic in the trace (its own too, and a
        // controller's diagnostics whatever their name): it reads them all.
        grant.subscribe = {"*"};
    } else {
        // A controller may publish diagnostics on topics of its own
        // (docs/controller-contract.md section 4), never on the table's others.
        grant.open_publish = {"*"};
    }
    return grant;
}

std::string governance_xml() {
    // Only authenticated participants join; every RTPS message between them is
    // encrypted and authenticated with the sender's session key (so an
    // outsider can neither read nor forge any of it, heartbeats and
    // acknowledgements included); endpoints are announced over the secure
    // discovery endpoints only, and every reader and writer is checked against
    // the remote's signed permissions. Data and metadata get no second layer
    // of protection: the message's covers them.
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
           "<!-- The sprayer HIL rig's domain governance for one run (rig run --dds-security; docs/dds-security.md). -->\n"
           "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\"\n"
           "     xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd\">\n"
           "  <domain_access_rules>\n"
           "    <domain_rule>\n"
           "      <domains><id_range><min>0</min><max>" +
           std::to_string(kLastDomain) +
           "</max></id_range></domains>\n"
           "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
           "      <enable_join_access_control>true</enable_join_access_control>\n"
           "      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>\n"
           "      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>\n"
           "      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>\n"
           "      <topic_access_rules>\n"
           "        <topic_rule>\n"
           "          <topic_expression>*</topic_expression>\n"
           "          <enable_discovery_protection>true</enable_discovery_protection>\n"
           "          <enable_liveliness_protection>false</enable_liveliness_protection>\n"
           "          <enable_read_access_control>true</enable_read_access_control>\n"
           "          <enable_write_access_control>true</enable_write_access_control>\n"
           "          <metadata_protection_kind>NONE</metadata_protection_kind>\n"
           "          <data_protection_kind>NONE</data_protection_kind>\n"
           "        </topic_rule>\n"
           "      </topic_access_rules>\n"
           "    </domain_rule>\n"
           "  </domain_access_rules>\n"
           "</dds>\n";
}

std::string permissions_xml(const std::string& identity, const std::string& subject_rfc2253,
                            const std::string& not_before, const std::string& not_after) {
    const TopicGrant grant = topic_grant(identity);
    const std::string domains = "      <domains><id_range><min>0</min><max>" + std::to_string(kLastDomain) +
                                "</max></id_range></domains>\n";
    auto rule = [&](const char* kind, const std::vector<std::string>& publish, const std::vector<std::string>& subscribe) {
        if (publish.empty() && subscribe.empty()) return std::string();
        std::string xml = std::string("    <") + kind + ">\n" + domains;
        if (!publish.empty()) xml += "      <publish>\n" + topics_element(publish, "        ") + "      </publish>\n";
        if (!subscribe.empty()) xml += "      <subscribe>\n" + topics_element(subscribe, "        ") + "      </subscribe>\n";
        return xml + "    </" + kind + ">\n";
    };
    // Fast DDS applies the first rule that names a topic: the table's grants,
    // then its denials, then what stays open (the controller's own topics).
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
           "<!-- What the " + identity + " may publish and subscribe in this run, from idl/topics.json (docs/dds-security.md). -->\n"
           "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\"\n"
           "     xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd\">\n"
           "  <permissions>\n"
           "  <grant name=\"" + identity + "\">\n"
           "    <subject_name>" + xml_escape(subject_rfc2253) + "</subject_name>\n"
           "    <validity><not_before>" + not_before + "</not_before><not_after>" + not_after + "</not_after></validity>\n" +
           rule("allow_rule", grant.publish, grant.subscribe) +
           rule("deny_rule", grant.denied_publish, grant.denied_subscribe) +
           rule("allow_rule", grant.open_publish, {}) +
           "    <default>DENY</default>\n"
           "  </grant>\n"
           "  </permissions>\n"
           "</dds>\n";
}

DdsSecurityRun make_dds_security_run(const std::filesystem::path& dir, const std::string& openssl_program) {
    DdsSecurityRun run{dir};
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::filesystem::permissions(dir, std::filesystem::perms::owner_all, std::filesystem::perm_options::replace);
    Openssl openssl(openssl_program, dir / "openssl.log");
    // The validity window is read from rig's clock (a label of the credentials, not of the trace).
    const std::string not_before = utc_date_time_from_now(-std::chrono::hours(24 * kValidDaysBefore));
    const std::string not_after = utc_date_time_from_now(std::chrono::hours(24 * kValidDaysAfter));
    const std::string days = std::to_string(kValidDaysAfter);
    auto new_key = [&](const std::filesystem::path& key) {
        create_private_file(key);
        openssl({"genpkey", "-algorithm", "EC", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-out", key.string()});
    };

    // The run's CA: it signs the identities, the governance and the permissions.
    const std::filesystem::path ca_key = dir / "ca-key.pem";
    const std::filesystem::path ca = dir / kSecurityCaFile;
    new_key(ca_key);
    openssl({"req", "-new", "-x509", "-key", ca_key.string(), "-subj",
             std::string("/O=") + kOrganisation + "/CN=rig run CA", "-days", days, "-sha256", "-out", ca.string()});
    auto sign = [&](const std::filesystem::path& document, const std::filesystem::path& signed_document) {
        // Clear-signed S/MIME, the text readable inside: what Fast DDS's Access-Permissions reads.
        openssl({"smime", "-sign", "-text", "-in", document.string(), "-out", signed_document.string(), "-signer",
                 ca.string(), "-inkey", ca_key.string()});
    };
    const std::filesystem::path governance = dir / "governance.xml";
    write_text(governance, governance_xml());
    sign(governance, dir / kSecurityGovernanceFile);

    int serial = 1;
    for (const std::string identity : {kRigIdentity, kControllerIdentity}) {
        const std::filesystem::path home = run.identity_dir(identity);
        std::filesystem::create_directories(home);
        const std::filesystem::path key = home / kSecurityPrivateKeyFile;
        const std::filesystem::path request = home / "cert.csr";
        new_key(key);
        openssl({"req", "-new", "-key", key.string(), "-subj", std::string("/O=") + kOrganisation + "/CN=" + identity,
                 "-out", request.string()});
        openssl({"x509", "-req", "-in", request.string(), "-CA", ca.string(), "-CAkey", ca_key.string(),
                 "-set_serial", std::to_string(++serial), "-days", days, "-sha256", "-out",
                 (home / kSecurityCertificateFile).string()});
        std::filesystem::remove(request);
        const std::filesystem::path permissions = home / "permissions.xml";
        write_text(permissions, permissions_xml(identity, subject_rfc2253(identity), not_before, not_after));
        sign(permissions, home / kSecurityPermissionsFile);
        std::filesystem::copy_file(ca, home / kSecurityCaFile);
        std::filesystem::copy_file(dir / kSecurityGovernanceFile, home / kSecurityGovernanceFile);
    }
    // Nothing more is signed for this run.
    std::filesystem::remove(ca_key);
    return run;
}

}  // namespace rig::harness
