#pragma once
// The one exception type for "this configuration is wrong": it points at the
// file, line, column and key, so a mistake in a case file is reported like a
// compiler error, before anything starts (docs/design.md "Case files").
#include <stdexcept>
#include <string>
#include <utility>

namespace rig {

// Where in a configuration file something is. Line and column are 1-based, as
// editors show them; 0 means "not known" (a file that cannot be read has no line).
struct SourceLocation {
    std::string file;
    int line = 0;
    int column = 0;
    // Dotted path of the key, with list indices: `gnss.dropouts[1].for_s`.
    // Empty means the document as a whole.
    std::string key_path;
};

// what() is `FILE:LINE:COL: KEY: MESSAGE`, e.g.
//   cases/bp.yaml:14:12: gnss.rate_hz: must be > 0, got -5
// which editors and CI log viewers turn into a link. When the line is not known
// (file missing, unreadable) it is `FILE: KEY: MESSAGE`; an empty key path is
// printed as `(document)`.
class ConfigError : public std::runtime_error {
public:
    ConfigError(SourceLocation where, std::string message)
        : std::runtime_error(format(where, message)), where_(std::move(where)), message_(std::move(message)) {}

    const SourceLocation& where() const { return where_; }
    const std::string& file() const { return where_.file; }
    int line() const { return where_.line; }
    int column() const { return where_.column; }
    const std::string& key_path() const { return where_.key_path; }
    // The message alone, without location and key.
    const std::string& message() const { return message_; }

    static std::string format(const SourceLocation& where, const std::string& message) {
        std::string text = where.file;
        if (where.line > 0) {
            text += ':' + std::to_string(where.line) + ':' + std::to_string(where.column > 0 ? where.column : 1);
        }
        text += ": ";
        text += where.key_path.empty() ? std::string("(document)") : where.key_path;
        text += ": ";
        text += message;
        return text;
    }

private:
    SourceLocation where_;
    std::string message_;
};

}  // namespace rig
