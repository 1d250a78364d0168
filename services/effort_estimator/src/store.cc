#include "tamp/effort_estimator/store.h"

#include <sqlite3.h>

#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>

#include "tamp/core/log.h"

namespace tamp::effort_estimator {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS records(
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  record_id TEXT UNIQUE,
  kind TEXT NOT NULL,
  duration_s REAL NOT NULL,
  timestamp_s REAL NOT NULL,
  source TEXT NOT NULL,
  features TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS models(kind TEXT PRIMARY KEY, model TEXT NOT NULL);
)sql";

/// RAII statement.
class Stmt {
 public:
  Stmt(sqlite3* db, const char* sql) { rc_ = sqlite3_prepare_v2(db, sql, -1, &s_, nullptr); }
  ~Stmt() { sqlite3_finalize(s_); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
  bool ok() const { return rc_ == SQLITE_OK && s_ != nullptr; }
  sqlite3_stmt* get() const { return s_; }

 private:
  sqlite3_stmt* s_{nullptr};
  int rc_{SQLITE_ERROR};
};

std::string text(sqlite3_stmt* s, int col) {
  const unsigned char* t = sqlite3_column_text(s, col);
  return t == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(t));
}

bool exec(sqlite3* db, const char* sql, std::string& why) {
  char* err = nullptr;
  const int rc = sqlite3_exec(db, sql, nullptr, nullptr, &err);
  if (rc != SQLITE_OK) {
    why = err != nullptr ? err : sqlite3_errstr(rc);
    sqlite3_free(err);
    return false;
  }
  return true;
}

json featuresToJson(const ActionFeatures& f) {
  return json{{"moves", f.moves.lengths()},
              {"turns", f.turns.lengths()},
              {"approach_m", f.approach_m},
              {"retreat_m", f.retreat_m},
              {"object_mass_kg", f.object_mass_kg}};
}

/// Throws (json or invalid_argument) on malformed content; the caller turns that into a warning.
ActionFeatures featuresFromJson(ActionKind kind, const json& j) {
  ActionFeatures f;
  f.kind = kind;
  f.moves = MoveSet(j.at("moves").get<std::vector<double>>());
  f.turns = MoveSet(j.at("turns").get<std::vector<double>>());
  f.approach_m = j.at("approach_m").get<double>();
  f.retreat_m = j.at("retreat_m").get<double>();
  f.object_mass_kg = j.at("object_mass_kg").get<double>();
  return f;
}

json modelToJson(const KindModel& m) {
  return json{{"kind", std::string(toString(m.kind))},
              {"parameter_names", m.parameter_names},
              {"values", m.values},
              {"log_covariance", m.log_covariance},
              {"noise_log_stddev", m.noise_log_stddev},
              {"version", m.version},
              {"record_count", m.record_count},
              {"fitted_at_s", m.fitted_at_s},
              {"summary",
               {{"converged", m.summary.converged},
                {"iterations", m.summary.iterations},
                {"passes", m.summary.passes},
                {"outliers", m.summary.outliers},
                {"rms_log_residual", m.summary.rms_log_residual},
                {"solve_time_s", m.summary.solve_time_s},
                {"covariance_ok", m.summary.covariance_ok},
                {"message", m.summary.message}}}};
}

KindModel modelFromJson(ActionKind kind, const json& j) {
  KindModel m;
  m.kind = kind;
  m.parameter_names = j.at("parameter_names").get<std::vector<std::string>>();
  m.values = j.at("values").get<std::vector<double>>();
  m.log_covariance = j.at("log_covariance").get<std::vector<double>>();
  m.noise_log_stddev = j.at("noise_log_stddev").get<double>();
  m.version = j.at("version").get<std::uint64_t>();
  m.record_count = j.at("record_count").get<std::uint64_t>();
  m.fitted_at_s = j.at("fitted_at_s").get<double>();
  const json& s = j.at("summary");
  m.summary.converged = s.at("converged").get<bool>();
  m.summary.iterations = s.at("iterations").get<int>();
  m.summary.passes = s.at("passes").get<int>();
  m.summary.outliers = s.at("outliers").get<int>();
  m.summary.rms_log_residual = s.at("rms_log_residual").get<double>();
  m.summary.solve_time_s = s.at("solve_time_s").get<double>();
  m.summary.covariance_ok = s.at("covariance_ok").get<bool>();
  m.summary.message = s.at("message").get<std::string>();
  return m;
}

double unixNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

struct EffortStore::Impl {
  sqlite3* db{nullptr};
  ~Impl() {
    if (db != nullptr) sqlite3_close(db);
  }
};

EffortStore::EffortStore(std::unique_ptr<Impl> impl, fs::path file)
    : impl_(std::move(impl)), file_(std::move(file)) {}
EffortStore::~EffortStore() = default;

std::unique_ptr<EffortStore> EffortStore::inMemory() {
  return std::unique_ptr<EffortStore>(new EffortStore(nullptr, {}));
}

bool EffortStore::persistent() const { return impl_ != nullptr && impl_->db != nullptr; }

namespace {

/// Opens `file` and makes sure it is a store of our schema. On failure `why` says what is wrong;
/// `corrupt` tells whether the file exists but is not usable (so it should be moved aside).
sqlite3* openAndCheck(const fs::path& file, std::string& why, bool& corrupt) {
  corrupt = false;
  sqlite3* db = nullptr;
  int rc = sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    why = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    sqlite3_close(db);
    return nullptr;
  }
  sqlite3_busy_timeout(db, 2000);
  auto fail = [&](const std::string& reason, bool is_corrupt) -> sqlite3* {
    why = reason;
    corrupt = is_corrupt;
    sqlite3_close(db);
    return nullptr;
  };
  {
    // quick_check reads every page: a truncated or overwritten file fails here (SQLITE_NOTADB,
    // SQLITE_CORRUPT) rather than on some later write.
    Stmt check(db, "PRAGMA quick_check;");
    if (!check.ok()) return fail(sqlite3_errmsg(db), true);
    rc = sqlite3_step(check.get());
    if (rc != SQLITE_ROW) return fail(sqlite3_errmsg(db), true);
    const std::string result = text(check.get(), 0);
    if (result != "ok") return fail("integrity check failed: " + result, true);
  }
  std::string err;
  if (!exec(db, "PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;", err)) return fail(err, true);
  if (!exec(db, kSchema, err)) return fail(err, true);
  {
    Stmt get(db, "SELECT value FROM meta WHERE key='schema_version';");
    if (!get.ok()) return fail(sqlite3_errmsg(db), true);
    if (sqlite3_step(get.get()) == SQLITE_ROW) {
      const std::string v = text(get.get(), 0);
      if (v != std::to_string(EffortStore::kSchemaVersion)) {
        return fail("schema version " + v + ", this build reads version " +
                        std::to_string(EffortStore::kSchemaVersion),
                    true);
      }
    } else {
      const std::string insert = "INSERT INTO meta(key, value) VALUES('schema_version', '" +
                                 std::to_string(EffortStore::kSchemaVersion) + "');";
      if (!exec(db, insert.c_str(), err)) return fail(err, true);
    }
  }
  // Columns of our schema must all be there (a foreign database with same-named tables).
  for (const char* probe : {"SELECT id, record_id, kind, duration_s, timestamp_s, source, features FROM records LIMIT 0;",
                            "SELECT kind, model FROM models LIMIT 0;"}) {
    Stmt s(db, probe);
    if (!s.ok()) return fail(std::string("unexpected table layout: ") + sqlite3_errmsg(db), true);
  }
  return db;
}

}  // namespace

StoreOpenResult EffortStore::open(const fs::path& directory, double max_record_duration_s) {
  StoreOpenResult out;
  auto log = tamp::log::get("effort_estimator");
  auto memoryOnly = [&](const std::string& why) {
    out.warnings.push_back(why + "; running without persistence (records and models are lost at exit)");
    out.store = inMemory();
    return std::move(out);
  };
  std::error_code ec;
  if (directory.empty()) {
    out.store = inMemory();
    return out;
  }
  if (!fs::exists(directory, ec)) {
    fs::create_directories(directory, ec);
    if (ec) {
      return memoryOnly("effort store directory '" + directory.string() + "' does not exist and cannot be created (" +
                        ec.message() + ")");
    }
    out.warnings.push_back("effort store directory '" + directory.string() +
                           "' did not exist; created it, starting from default models");
  } else if (!fs::is_directory(directory, ec)) {
    return memoryOnly("effort store path '" + directory.string() + "' exists but is not a directory");
  }
  const fs::path file = directory / kFileName;
  std::string why;
  bool corrupt = false;
  sqlite3* db = openAndCheck(file, why, corrupt);
  if (db == nullptr && corrupt) {
    const fs::path aside = file.string() + ".corrupt-" + std::to_string(static_cast<long long>(unixNow()));
    fs::rename(file, aside, ec);
    if (ec) return memoryOnly("effort store '" + file.string() + "' is unusable (" + why + ") and cannot be moved aside (" + ec.message() + ")");
    for (const char* suffix : {"-wal", "-shm"}) fs::remove(file.string() + suffix, ec);
    out.warnings.push_back("effort store '" + file.string() + "' is unusable (" + why + "); moved it to '" +
                           aside.string() + "' and started from default models");
    db = openAndCheck(file, why, corrupt);
  }
  if (db == nullptr) return memoryOnly("cannot open effort store '" + file.string() + "' (" + why + ")");

  auto impl = std::make_unique<Impl>();
  impl->db = db;
  out.store = std::unique_ptr<EffortStore>(new EffortStore(std::move(impl), file));

  // Read back records and models; skip (and name) invalid rows.
  {
    Stmt s(db, "SELECT id, record_id, kind, duration_s, timestamp_s, source, features FROM records ORDER BY id;");
    while (s.ok() && sqlite3_step(s.get()) == SQLITE_ROW) {
      const long long id = sqlite3_column_int64(s.get(), 0);
      const std::string kind_name = text(s.get(), 2);
      std::string problem;
      try {
        const auto kind = actionKindFromString(kind_name);
        if (!kind) throw std::invalid_argument("unknown action kind '" + kind_name + "'");
        FeatureRecord r;
        r.record_id = text(s.get(), 1);
        r.duration_s = sqlite3_column_double(s.get(), 3);
        r.timestamp_s = sqlite3_column_double(s.get(), 4);
        r.source = text(s.get(), 5);
        r.features = featuresFromJson(*kind, json::parse(text(s.get(), 6)));
        if (Status st = validateFeatureRecord(r, max_record_duration_s); !st) throw std::invalid_argument(st.error().toString());
        out.records.push_back(std::move(r));
      } catch (const std::exception& e) {
        ++out.rows_skipped;
        out.warnings.push_back("effort store '" + file.string() + "': skipped record row " + std::to_string(id) + ": " + e.what());
      }
    }
  }
  {
    Stmt s(db, "SELECT kind, model FROM models;");
    while (s.ok() && sqlite3_step(s.get()) == SQLITE_ROW) {
      const std::string kind_name = text(s.get(), 0);
      try {
        const auto kind = actionKindFromString(kind_name);
        if (!kind) throw std::invalid_argument("unknown action kind");
        KindModel m = modelFromJson(*kind, json::parse(text(s.get(), 1)));
        if (Status st = m.validate(); !st) throw std::invalid_argument(st.error().toString());
        out.models.push_back(std::move(m));
      } catch (const std::exception& e) {
        ++out.rows_skipped;
        out.warnings.push_back("effort store '" + file.string() + "': ignored the stored '" + kind_name +
                               "' model (" + e.what() + "); that kind starts from its defaults");
      }
    }
  }
  log->debug("effort store {}: {} records, {} models", file.string(), out.records.size(), out.models.size());
  return out;
}

Status EffortStore::appendRecord(const FeatureRecord& r) {
  if (!persistent()) return Status::Ok();
  sqlite3* db = impl_->db;
  Stmt s(db, "INSERT INTO records(record_id, kind, duration_s, timestamp_s, source, features) VALUES(?,?,?,?,?,?);");
  if (!s.ok()) return Error(ErrorCode::kIo, std::string("cannot prepare insert: ") + sqlite3_errmsg(db), SourceLocation{file_.string()});
  const std::string kind(toString(r.features.kind));
  const std::string features = featuresToJson(r.features).dump();
  if (r.record_id.empty()) {
    sqlite3_bind_null(s.get(), 1);
  } else {
    sqlite3_bind_text(s.get(), 1, r.record_id.c_str(), -1, SQLITE_TRANSIENT);
  }
  sqlite3_bind_text(s.get(), 2, kind.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_double(s.get(), 3, r.duration_s);
  sqlite3_bind_double(s.get(), 4, r.timestamp_s);
  sqlite3_bind_text(s.get(), 5, r.source.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(s.get(), 6, features.c_str(), -1, SQLITE_TRANSIENT);
  if (sqlite3_step(s.get()) != SQLITE_DONE) {
    return Error(ErrorCode::kIo, std::string("cannot store record: ") + sqlite3_errmsg(db), SourceLocation{file_.string()});
  }
  return Status::Ok();
}

Status EffortStore::saveModel(const KindModel& m) {
  if (!persistent()) return Status::Ok();
  sqlite3* db = impl_->db;
  Stmt s(db, "INSERT OR REPLACE INTO models(kind, model) VALUES(?, ?);");
  if (!s.ok()) return Error(ErrorCode::kIo, std::string("cannot prepare model write: ") + sqlite3_errmsg(db), SourceLocation{file_.string()});
  const std::string kind(toString(m.kind));
  const std::string body = modelToJson(m).dump();
  sqlite3_bind_text(s.get(), 1, kind.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(s.get(), 2, body.c_str(), -1, SQLITE_TRANSIENT);
  if (sqlite3_step(s.get()) != SQLITE_DONE) {
    return Error(ErrorCode::kIo, std::string("cannot store model: ") + sqlite3_errmsg(db), SourceLocation{file_.string()});
  }
  return Status::Ok();
}

}  // namespace tamp::effort_estimator
