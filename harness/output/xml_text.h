#pragma once
// Text the rig writes into files people and tools read (results.json,
// junit.xml, report.html): always valid UTF-8, and escaped for XML where it
// goes into XML. Error text can come from a crashed child's output, so
// nothing here trusts its input.
#include <string>
#include <string_view>

namespace rig::harness {

// The text with malformed UTF-8 replaced by U+FFFD (nlohmann::json refuses to
// dump invalid UTF-8).
std::string valid_utf8(std::string_view text);

// Escapes for XML (and so XHTML) element text, or for a double-quoted attribute
// value; malformed UTF-8 and characters XML 1.0 forbids become U+FFFD.
std::string xml_escape(std::string_view text, bool attribute);

}  // namespace rig::harness
