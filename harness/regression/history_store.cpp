#include "harness/regression/history_store.h"

#include <sqlite3.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <regex>
#include <set>
#include <system_error>
#include <tuple>
#include <utility>

namespace rig::harness {

namespace {

namespace fs = std::filesystem;

// The few calls of SQLite's C interface the history needs, each failure
// thrown as E naming the database file.
template <typename E>
class Statement {
public:
    Statement(sqlite3* db, const fs::path& file, const std::string& sql) : db_(db), file_(file) {
        if (sqlite3_prepare_v2(db, sql.c_str(), -1, &statement_, nullptr) != SQLITE_OK) fail("cannot read it");
    }
    Statement(const Statement&) = delete;
    Statement& operator=(const Statement&) = delete;
    ~Statement() { sqlite3_finalize(statement_); }

    Statement& bind(int index, const std::string& text) {
        check(sqlite3_bind_text(statement_, index, text.c_str(), static_cast<int>(text.size()), SQLITE_TRANSIENT));
        return *this;
    }
    Statement& bind(int index, std::int64_t number) {
        check(sqlite3_bind_int64(statement_, index, number));
        return *this;
    }
    Statement& bind(int index, const std::optional<double>& number) {
        check(number ? sqlite3_bind_double(statement_, index, *number) : sqlite3_bind_null(statement_, index));
        return *this;
    }
    // True while there is a row to read.
    bool step() {
        const int status = sqlite3_step(statement_);
        if (status == SQLITE_ROW) return true;
        if (status != SQLITE_DONE) fail("cannot read or write it");
        return false;
    }
    // Runs an insert or delete, and makes the statement ready for the next binding.
    void run() {
        step();
        sqlite3_reset(statement_);
        sqlite3_clear_bindings(statement_);
    }
    std::string text(int column) const {
        const unsigned char* value = sqlite3_column_text(statement_, column);
        return value == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(value));
    }
    std::int64_t integer(int column) const { return sqlite3_column_int64(statement_, column); }
    std::optional<double> real(int column) const {
        if (sqlite3_column_type(statement_, column) == SQLITE_NULL) return std::nullopt;
        return sqlite3_column_double(statement_, column);
    }

private:
    void check(int status) {
        if (status != SQLITE_OK) fail("cannot write it");
    }
    [[noreturn]] void fail(const char* what) {
        throw E(file_.string() + ": " + what + ": " + sqlite3_errmsg(db_));
    }
    sqlite3* db_;
    fs::path file_;
    sqlite3_stmt* statement_ = nullptr;
};

class Connection {
public:
    Connection(const fs::path& file, int flags) : file_(file) {
        if (sqlite3_open_v2(file.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
            const std::string why = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
            sqlite3_close(db_);
            throw HistoryUnreadable(file.string() + ": cannot open the history database: " + why);
        }
        sqlite3_extended_result_codes(db_, 1);
    }
    Connection(const Connection&) = delete;
    Connection& operator=(const Connection&) = delete;
    ~Connection() { sqlite3_close(db_); }

    template <typename E>
    void exec(const std::string& sql) {
        char* message = nullptr;
        if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
            const std::string why = message != nullptr ? message : sqlite3_errmsg(db_);
            sqlite3_free(message);
            throw E(file_.string() + ": " + why);
        }
    }
    template <typename E>
    Statement<E> prepare(const std::string& sql) {
        return Statement<E>(db_, file_, sql);
    }

private:
    fs::path file_;
    sqlite3* db_ = nullptr;
};

constexpr const char* kSchema = R"sql(
CREATE TABLE history_schema (version INTEGER NOT NULL);
CREATE TABLE entries (
  id INTEGER PRIMARY KEY,
  branch TEXT NOT NULL,
  commit_sha TEXT NOT NULL,
  commit_order INTEGER NOT NULL,
  date TEXT NOT NULL,
  source TEXT NOT NULL,
  kind TEXT NOT NULL,
  rig_version TEXT NOT NULL,
  rig_commit TEXT NOT NULL,
  UNIQUE (branch, commit_sha),
  UNIQUE (branch, commit_order));
CREATE TABLE cases (
  entry_id INTEGER NOT NULL REFERENCES entries(id) ON DELETE CASCADE,
  case_name TEXT NOT NULL,
  file TEXT NOT NULL,
  PRIMARY KEY (entry_id, case_name));
CREATE TABLE limits (
  entry_id INTEGER NOT NULL REFERENCES entries(id) ON DELETE CASCADE,
  case_name TEXT NOT NULL, metric TEXT NOT NULL, value REAL NOT NULL,
  PRIMARY KEY (entry_id, case_name, metric));
CREATE TABLE min_effects (
  entry_id INTEGER NOT NULL REFERENCES entries(id) ON DELETE CASCADE,
  case_name TEXT NOT NULL, metric TEXT NOT NULL, value REAL NOT NULL,
  PRIMARY KEY (entry_id, case_name, metric));
CREATE TABLE runs (
  entry_id INTEGER NOT NULL REFERENCES entries(id) ON DELETE CASCADE,
  case_name TEXT NOT NULL, seed INTEGER NOT NULL, run TEXT NOT NULL, passed INTEGER NOT NULL,
  error TEXT NOT NULL, trace_sha256 TEXT NOT NULL, case_sha256 TEXT NOT NULL,
  controller_sha256 TEXT NOT NULL, controller_config_sha256 TEXT NOT NULL,
  PRIMARY KEY (entry_id, case_name, seed));
CREATE TABLE metric_values (
  entry_id INTEGER NOT NULL REFERENCES entries(id) ON DELETE CASCADE,
  case_name TEXT NOT NULL, seed INTEGER NOT NULL, metric TEXT NOT NULL,
  value REAL, not_measured TEXT,
  PRIMARY KEY (entry_id, case_name, seed, metric));
)sql";

// The schema version of an open database; 0 for an empty one (a new file).
int schema_version(Connection& db, const fs::path& file) {
    // Reading the catalogue is the first read of the file: a file that is not
    // SQLite fails here ("file is not a database").
    Statement<HistoryUnreadable> tables = db.prepare<HistoryUnreadable>(
        "SELECT name FROM sqlite_master WHERE type = 'table'");
    std::set<std::string> names;
    while (tables.step()) names.insert(tables.text(0));
    if (names.empty()) return 0;
    if (!names.count("history_schema")) {
        throw HistoryUnreadable(file.string() + ": an SQLite database, but not a rig history (no history_schema table)");
    }
    Statement<HistoryUnreadable> version = db.prepare<HistoryUnreadable>("SELECT version FROM history_schema");
    if (!version.step()) throw HistoryUnreadable(file.string() + ": history_schema holds no version");
    const std::int64_t found = version.integer(0);
    if (found != kHistorySchemaVersion) {
        throw HistoryUnreadable(file.string() + ": history schema version " + std::to_string(found) +
                                ", this rig reads version " + std::to_string(kHistorySchemaVersion));
    }
    return static_cast<int>(found);
}

std::string checked_commit(const std::string& commit) {
    static const std::regex hex("[0-9a-fA-F]{4,64}");
    if (!std::regex_match(commit, hex)) {
        throw std::invalid_argument("--commit '" + commit + "' is not a commit id (4 to 64 hex digits)");
    }
    std::string lower = commit;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    return lower;
}

void check_branch(const std::string& branch) {
    const bool printable = std::all_of(branch.begin(), branch.end(), [](unsigned char c) { return c > ' ' && c != 0x7f; });
    if (branch.empty() || !printable) {
        throw std::invalid_argument("--branch '" + branch + "' is not a branch name (no spaces or control characters)");
    }
}

void check_date(const std::string& date) {
    static const std::regex iso8601(R"(\d{4}-\d{2}-\d{2}([T ]\d{2}:\d{2}(:\d{2}(\.\d+)?)?(Z|[+-]\d{2}:?\d{2})?)?)");
    if (!date.empty() && !std::regex_match(date, iso8601)) {
        throw std::invalid_argument("--date '" + date + "' is not an ISO 8601 date (2026-11-27 or 2026-11-27T23:57:47Z)");
    }
}

// The entry's rows, inside the open transaction.
HistoryAdded insert_entry(Connection& db, const RunSamples& samples, const HistoryEntryOptions& options,
                          const std::string& commit, const fs::path& file) {
    using E = HistoryNotAdded;
    HistoryAdded added;
    std::optional<std::int64_t> kept_order;
    Statement<E> existing = db.prepare<E>("SELECT id, commit_order FROM entries WHERE branch = ?1 AND commit_sha = ?2");
    existing.bind(1, options.branch).bind(2, commit);
    if (existing.step()) {
        if (!options.replace) {
            throw HistoryNotAdded(file.string() + ": commit " + commit + " is already in the history of branch '" +
                                  options.branch + "' (order " + std::to_string(existing.integer(1)) +
                                  "); add --replace to replace its entry");
        }
        kept_order = existing.integer(1);
        Statement<E> remove = db.prepare<E>("DELETE FROM entries WHERE id = ?1");
        remove.bind(1, existing.integer(0)).run();
        added.replaced = true;
    }
    if (options.order) {
        added.order = *options.order;
    } else if (kept_order) {
        added.order = *kept_order;
    } else {
        Statement<E> highest = db.prepare<E>("SELECT MAX(commit_order) FROM entries WHERE branch = ?1");
        highest.bind(1, options.branch);
        added.order = highest.step() && highest.real(0) ? highest.integer(0) + 1 : 1;
    }
    Statement<E> taken = db.prepare<E>("SELECT commit_sha FROM entries WHERE branch = ?1 AND commit_order = ?2");
    taken.bind(1, options.branch).bind(2, added.order);
    if (taken.step()) {
        throw HistoryNotAdded(file.string() + ": order " + std::to_string(added.order) + " of branch '" +
                              options.branch + "' is commit " + taken.text(0) + "'s; give another --order");
    }
    added.date = options.date.empty() ? samples.started_utc : options.date;

    Statement<E> entry = db.prepare<E>(
        "INSERT INTO entries (branch, commit_sha, commit_order, date, source, kind, rig_version, rig_commit) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)");
    entry.bind(1, options.branch).bind(2, commit).bind(3, added.order).bind(4, added.date);
    entry.bind(5, samples.source.string()).bind(6, samples.kind).bind(7, samples.rig_version).bind(8, samples.rig_commit);
    entry.run();
    Statement<E> id = db.prepare<E>("SELECT last_insert_rowid()");
    id.step();
    const std::int64_t entry_id = id.integer(0);

    Statement<E> one_case = db.prepare<E>("INSERT INTO cases (entry_id, case_name, file) VALUES (?1, ?2, ?3)");
    Statement<E> limit = db.prepare<E>("INSERT INTO limits (entry_id, case_name, metric, value) VALUES (?1, ?2, ?3, ?4)");
    Statement<E> effect =
        db.prepare<E>("INSERT INTO min_effects (entry_id, case_name, metric, value) VALUES (?1, ?2, ?3, ?4)");
    Statement<E> run = db.prepare<E>(
        "INSERT INTO runs (entry_id, case_name, seed, run, passed, error, trace_sha256, case_sha256, "
        "controller_sha256, controller_config_sha256) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)");
    Statement<E> value = db.prepare<E>(
        "INSERT INTO metric_values (entry_id, case_name, seed, metric, value, not_measured) VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
    for (const CaseSamples& samples_of_case : samples.cases) {
        const std::string& name = samples_of_case.name;
        one_case.bind(1, entry_id).bind(2, name).bind(3, samples_of_case.file).run();
        for (const auto& [metric, number] : samples_of_case.limits) {
            limit.bind(1, entry_id).bind(2, name).bind(3, metric).bind(4, std::optional<double>(number)).run();
        }
        for (const auto& [metric, number] : samples_of_case.min_effects) {
            effect.bind(1, entry_id).bind(2, name).bind(3, metric).bind(4, std::optional<double>(number)).run();
        }
        for (const RunSample& sample : samples_of_case.runs) {
            const auto seed = static_cast<std::int64_t>(sample.seed);
            run.bind(1, entry_id).bind(2, name).bind(3, seed).bind(4, sample.run);
            run.bind(5, std::int64_t{sample.passed ? 1 : 0}).bind(6, sample.error).bind(7, sample.trace_sha256);
            run.bind(8, sample.case_sha256).bind(9, sample.controller_sha256).bind(10, sample.controller_config_sha256);
            run.run();
            for (const auto& [metric, number] : sample.metrics) {
                value.bind(1, entry_id).bind(2, name).bind(3, seed).bind(4, metric);
                value.bind(5, std::optional<double>(number)).run();
                ++added.values;
            }
            for (const auto& [metric, why] : sample.not_measured) {
                value.bind(1, entry_id).bind(2, name).bind(3, seed).bind(4, metric);
                value.bind(5, std::optional<double>()).bind(6, why).run();
                ++added.values;
            }
            ++added.runs;
        }
        ++added.cases;
    }
    return added;
}

}  // namespace

HistoryAdded add_to_history(const fs::path& database, const RunSamples& samples, const HistoryEntryOptions& options) {
    const std::string commit = checked_commit(options.commit);
    check_branch(options.branch);
    check_date(options.date);
    if (options.order && *options.order < 0) throw std::invalid_argument("--order must be 0 or more");
    if (samples.cases.empty()) {
        throw std::invalid_argument(samples.source.string() + ": no cases in it, nothing to add to " + database.string());
    }
    std::error_code error;
    if (fs::is_directory(database, error)) {
        throw HistoryUnreadable(database.string() + ": is a directory, not a history database file");
    }
    const bool existed = fs::exists(database, error);
    HistoryAdded added;
    {
        std::optional<Connection> db;
        db.emplace(database, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
        try {
            db->exec<HistoryUnreadable>("PRAGMA foreign_keys = ON");
            const bool fresh = schema_version(*db, database) == 0;
            // IMMEDIATE: the write lock is taken now, so a second writer fails
            // at once ("database is locked") rather than halfway through.
            db->exec<HistoryNotAdded>("BEGIN IMMEDIATE");
            try {
                if (fresh) {
                    db->exec<HistoryNotAdded>(kSchema);
                    db->exec<HistoryNotAdded>("INSERT INTO history_schema (version) VALUES (" +
                                              std::to_string(kHistorySchemaVersion) + ")");
                }
                added = insert_entry(*db, samples, options, commit, database);
                db->exec<HistoryNotAdded>("COMMIT");
            } catch (...) {
                try {
                    db->exec<HistoryNotAdded>("ROLLBACK");
                } catch (const std::exception&) {
                    // SQLite has rolled back already when the failure was a full disk or I/O error.
                }
                throw;
            }
        } catch (...) {
            db.reset();
            if (!existed) fs::remove(database, error);
            throw;
        }
    }
    added.created = !existed;
    return added;
}

History read_history(const fs::path& database) {
    using E = HistoryUnreadable;
    std::error_code error;
    if (!fs::exists(database, error)) throw E(database.string() + ": no such history database");
    if (fs::is_directory(database, error)) throw E(database.string() + ": is a directory, not a history database file");
    Connection db(database, SQLITE_OPEN_READONLY);
    if (schema_version(db, database) == 0) {
        throw E(database.string() + ": an empty SQLite database, not a rig history (rig history add makes one)");
    }
    History history;
    history.database = database;

    // Entries by branch and order; where each entry's commit sits.
    std::map<std::string, BranchHistory> branches;
    std::map<std::int64_t, std::pair<std::string, std::size_t>> entry_place;  // id -> (branch, commit index)
    std::int64_t newest_id = -1;
    Statement<E> entries = db.prepare<E>(
        "SELECT id, branch, commit_sha, commit_order, date, source, kind, rig_version, rig_commit FROM entries "
        "ORDER BY branch, commit_order");
    while (entries.step()) {
        BranchHistory& branch = branches[entries.text(1)];
        branch.branch = entries.text(1);
        HistoryCommit commit;
        commit.commit = entries.text(2);
        commit.order = entries.integer(3);
        commit.date = entries.text(4);
        commit.source = entries.text(5);
        commit.kind = entries.text(6);
        commit.rig_version = entries.text(7);
        commit.rig_commit = entries.text(8);
        entry_place[entries.integer(0)] = {branch.branch, branch.commits.size()};
        branch.commits.push_back(std::move(commit));
        if (entries.integer(0) > newest_id) {
            newest_id = entries.integer(0);
            history.newest_branch = branch.branch;
        }
    }
    auto commit_of = [&](std::int64_t entry_id) -> HistoryCommit& {
        const auto& [branch, index] = entry_place.at(entry_id);
        return branches.at(branch).commits[index];
    };

    Statement<E> digests = db.prepare<E>(
        "SELECT entry_id, controller_sha256, controller_config_sha256 FROM runs ORDER BY entry_id, case_name, seed");
    std::map<std::int64_t, std::pair<std::set<std::string>, std::set<std::string>>> digests_of;
    while (digests.step()) {
        digests_of[digests.integer(0)].first.insert(digests.text(1));
        digests_of[digests.integer(0)].second.insert(digests.text(2));
    }
    for (const auto& [entry_id, found] : digests_of) {
        auto one = [](const std::set<std::string>& all) { return all.size() == 1 ? *all.begin() : std::string("mixed"); };
        commit_of(entry_id).controller_sha256 = one(found.first);
        commit_of(entry_id).controller_config_sha256 = one(found.second);
    }

    using Key = std::tuple<std::int64_t, std::string, std::string>;  // entry, case, metric
    auto numbers = [&](const char* table) {
        std::map<Key, double> found;
        Statement<E> rows = db.prepare<E>(std::string("SELECT entry_id, case_name, metric, value FROM ") + table);
        while (rows.step()) found[{rows.integer(0), rows.text(1), rows.text(2)}] = rows.real(3).value_or(0.0);
        return found;
    };
    const std::map<Key, double> limits = numbers("limits");
    const std::map<Key, double> min_effects = numbers("min_effects");

    // Every value, grouped into series (branch, case, metric) and points (an entry).
    std::map<std::tuple<std::string, std::string, std::string>, std::map<std::size_t, HistoryPoint>> series;
    Statement<E> values = db.prepare<E>(
        "SELECT entry_id, case_name, metric, seed, value FROM metric_values ORDER BY entry_id, case_name, metric, seed");
    while (values.step()) {
        const std::int64_t entry_id = values.integer(0);
        const auto found = entry_place.find(entry_id);
        if (found == entry_place.end()) throw E(database.string() + ": a value of entry " + std::to_string(entry_id) + ", which is not in entries");
        const std::string case_name = values.text(1), metric = values.text(2);
        HistoryPoint& point = series[{found->second.first, case_name, metric}][found->second.second];
        if (point.seeds.empty()) {
            point.commit_index = found->second.second;
            const Key key{entry_id, case_name, metric};
            if (limits.count(key)) point.limit = limits.at(key);
            if (min_effects.count(key)) point.case_min_effect = min_effects.at(key);
        }
        point.seeds.push_back({static_cast<std::uint64_t>(values.integer(3)), values.real(4)});
    }
    for (auto& [key, points] : series) {
        HistorySeries one;
        one.case_name = std::get<1>(key);
        one.metric = std::get<2>(key);
        for (auto& [index, point] : points) one.points.push_back(std::move(point));
        branches.at(std::get<0>(key)).series.push_back(std::move(one));
    }
    for (auto& [name, branch] : branches) history.branches.push_back(std::move(branch));
    return history;
}

}  // namespace rig::harness
