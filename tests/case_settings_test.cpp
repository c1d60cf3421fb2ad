// `--set KEY=VALUE` (harness/spec/case_settings.h): a value of a case file
// replaced by its path before the loader reads it, so the key's own bounds
// and the rest of the loader's checks apply to it; an unknown path, a
// malformed setting, a key set twice or a value that is not one are errors
// naming what and where.
#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "harness/spec/case_settings.h"
#include "harness/systems/systems.h"
#include "run_support.h"

namespace fs = std::filesystem;
using namespace rig::harness;

namespace {

const fs::path kShortCase = RIG_SOURCE_DIR "/tests/data/short-fusion.yaml";

std::string message_of(const std::function<void()>& action) {
    try {
        action();
    } catch (const std::exception& error) {
        return error.what();
    }
    return "(no error)";
}

}  // namespace

TEST(KeySetting, ParsesKeyPathsWithListIndicesAndPlainValues) {
    const KeySetting setting = parse_key_setting("gnss.dropouts[0].for_s=2.5");
    EXPECT_EQ(setting.key, "gnss.dropouts[0].for_s");
    EXPECT_EQ(setting.value, "2.5");
    EXPECT_EQ(parse_key_setting("controller.positioning=rtk_only").value, "rtk_only");
    EXPECT_EQ(parse_key_setting("vehicle.speed_km_h=-1e-05").value, "-1e-05");
}

TEST(KeySetting, RefusesMalformedSettingsSayingWhy) {
    EXPECT_NE(message_of([] { parse_key_setting("vehicle.speed_km_h"); }).find("is not KEY=VALUE"), std::string::npos);
    EXPECT_NE(message_of([] { parse_key_setting("vehicle.speed_km_h="); }).find("the value is empty"), std::string::npos);
    EXPECT_NE(message_of([] { parse_key_setting("=3"); }).find("the key is empty"), std::string::npos);
    EXPECT_NE(message_of([] { parse_key_setting("vehicle..speed=3"); }).find("key name is missing"), std::string::npos);
    EXPECT_NE(message_of([] { parse_key_setting("gnss.dropouts[x].for_s=3"); }).find("list index"), std::string::npos);
    // Anything YAML reads as structure would change the file's shape, not a value.
    EXPECT_NE(message_of([] { parse_key_setting("vehicle.speed_km_h={a: 1}"); }).find("number or a word"),
              std::string::npos);
    EXPECT_NE(message_of([] { parse_key_setting("vehicle.speed_km_h=3 # x"); }).find("number or a word"),
              std::string::npos);
}

TEST(KeySetting, ReplacesTheWrittenValueOnlyKeepingCommentsAndLayout) {
    const std::string text =
        "name: c  # the case\n"
        "vehicle: { speed_km_h: 6.0, accel_m_s2: 0.5 }   # keep me\n"
        "gnss:\n"
        "  latency_s: 0.1\n"
        "  dropouts: [ { at_s: 3, for_s: 2.0 }, { at_s: 9, for_s: 1 } ]\n";
    const std::vector<KeySetting> settings = {{"vehicle.speed_km_h", "9.25"}, {"gnss.dropouts[1].at_s", "12"},
                                              {"gnss.latency_s", "0.3"}};
    EXPECT_EQ(apply_key_settings(text, "c.yaml", settings),
              "name: c  # the case\n"
              "vehicle: { speed_km_h: 9.25, accel_m_s2: 0.5 }   # keep me\n"
              "gnss:\n"
              "  latency_s: 0.3\n"
              "  dropouts: [ { at_s: 3, for_s: 2.0 }, { at_s: 12, for_s: 1 } ]\n");
    const WrittenValue written = written_value(text, "c.yaml", "gnss.dropouts[0].for_s");
    EXPECT_EQ(written.text, "2.0");
    EXPECT_EQ(written.where.line, 5);
}

TEST(KeySetting, AnUnwrittenPathIsAnErrorNamingItAndTheNearestWrittenKey) {
    const std::string text = "vehicle: { speed_km_h: 6.0 }\ngnss: { dropouts: [ { at_s: 3, for_s: 2 } ] }\n";
    const std::string typo = message_of([&] { written_value(text, "c.yaml", "vehicle.speed_kmh"); });
    EXPECT_NE(typo.find("c.yaml: vehicle.speed_kmh: the file writes no 'vehicle.speed_kmh'"), std::string::npos) << typo;
    EXPECT_NE(typo.find("did you mean 'vehicle.speed_km_h'"), std::string::npos) << typo;
    const std::string past_end = message_of([&] { written_value(text, "c.yaml", "gnss.dropouts[1].at_s"); });
    EXPECT_NE(past_end.find("the list has 1 item(s)"), std::string::npos) << past_end;
    const std::string section = message_of([&] { written_value(text, "c.yaml", "vehicle"); });
    EXPECT_NE(section.find("c.yaml:1:10: vehicle: is a mapping"), std::string::npos) << section;
    const std::string twice = message_of([&] {
        apply_key_settings(text, "c.yaml", std::vector<KeySetting>{{"vehicle.speed_km_h", "3"}, {"vehicle.speed_km_h", "4"}});
    });
    EXPECT_NE(twice.find("set twice (3 and 4)"), std::string::npos) << twice;
}

TEST(KeySetting, TheLoaderChecksASetValueAgainstTheKeysOwnBoundsNamingTheSetting) {
    const CaseSpec base = load_case_file(kShortCase);
    const CaseSpec faster = load_case_file(kShortCase, std::vector<KeySetting>{{"vehicle.speed_km_h", "9"}});
    EXPECT_NE(faster.source_text, base.source_text);
    EXPECT_NE(faster.source_text.find("speed_km_h: 9,"), std::string::npos);
    ASSERT_EQ(faster.settings.size(), 1u);
    EXPECT_EQ(faster.settings[0].key, "vehicle.speed_km_h");
    // The same bounds as the file's own value, reported at the file's line.
    const std::string too_fast =
        message_of([] { load_case_file(kShortCase, std::vector<KeySetting>{{"vehicle.speed_km_h", "400"}}); });
    EXPECT_NE(too_fast.find("short-fusion.yaml:7:"), std::string::npos) << too_fast;
    EXPECT_NE(too_fast.find("vehicle.speed_km_h: must be"), std::string::npos) << too_fast;
    EXPECT_NE(too_fast.find("(the value of --set vehicle.speed_km_h=400)"), std::string::npos) << too_fast;
    // A word where a number belongs is the loader's type error.
    const std::string word =
        message_of([] { load_case_file(kShortCase, std::vector<KeySetting>{{"gnss.latency_s", "fast"}}); });
    EXPECT_NE(word.find("gnss.latency_s"), std::string::npos) << word;
    EXPECT_NE(word.find("--set gnss.latency_s=fast"), std::string::npos) << word;
}

TEST(KeySetting, FolderExpansionLeavesSearchFilesOut) {
    const fs::path dir = rig::testing::fresh_dir("settings_search_files");
    fs::copy_file(kShortCase, dir / "a.yaml");
    { std::ofstream(dir / "a.search.yaml") << "search: { case: a.yaml, vary: [ \"vehicle.speed_km_h=3:9\" ] }\n"; }
    const std::vector<fs::path> paths = expand_case_paths({dir.string()});
    ASSERT_EQ(paths.size(), 1u);
    EXPECT_EQ(paths[0].filename(), "a.yaml");
    EXPECT_TRUE(is_search_file(dir / "a.search.yaml"));
    EXPECT_FALSE(is_search_file(dir / "a.yaml"));
}
