#include "server/job_store.h"

#include <sqlite3.h>

namespace penumbra::server {
namespace {

// One prepared statement, finalised on every path out.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK)
      throw StoreError(std::string("sqlite prepare: ") + sqlite3_errmsg(db));
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, const std::string& v) {
    check(sqlite3_bind_text(stmt_, i, v.data(), int(v.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Statement& bind(int i, int64_t v) {
    check(sqlite3_bind_int64(stmt_, i, v));
    return *this;
  }
  Statement& bind(int i, double v) {
    check(sqlite3_bind_double(stmt_, i, v));
    return *this;
  }
  Statement& bind_null(int i) {
    check(sqlite3_bind_null(stmt_, i));
    return *this;
  }
  bool step() {  // true while there is a row
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw StoreError(std::string("sqlite step: ") + sqlite3_errmsg(db_));
  }
  std::string text(int col) const {
    const auto* p = sqlite3_column_text(stmt_, col);
    return p ? std::string(reinterpret_cast<const char*>(p), sqlite3_column_bytes(stmt_, col)) : "";
  }
  int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }
  double real(int col) const { return sqlite3_column_double(stmt_, col); }

 private:
  void check(int rc) {
    if (rc != SQLITE_OK) throw StoreError(std::string("sqlite bind: ") + sqlite3_errmsg(db_));
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

constexpr const char* kColumns =
    "id, seq, state, idempotency_key, created_at, started_at, finished_at, attempts, width, height, "
    "spp, samples_total, stats, error, warnings";

JobRecord read_record(const Statement& s) {
  JobRecord r;
  r.id = s.text(0);
  r.seq = s.integer(1);
  r.state = job_state_from_string(s.text(2)).value_or(JobState::kFailed);
  r.idempotency_key = s.text(3);
  r.created_at = s.real(4);
  r.started_at = s.real(5);
  r.finished_at = s.real(6);
  r.attempts = int(s.integer(7));
  r.width = int(s.integer(8));
  r.height = int(s.integer(9));
  r.spp = int(s.integer(10));
  r.samples_total = uint64_t(s.integer(11));
  r.stats_json = s.text(12);
  r.error_json = s.text(13);
  r.warnings_json = s.text(14);
  return r;
}

}  // namespace

JobStore::JobStore(const std::string& path) {
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
                      nullptr) != SQLITE_OK) {
    const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw StoreError("cannot open " + path + ": " + msg);
  }
  sqlite3_busy_timeout(db_, 5000);
  // WAL: readers never wait for the writer. synchronous=FULL: a commit is on disk before
  // the 202 goes out, so even a power cut cannot lose an accepted job.
  exec("PRAGMA journal_mode=WAL");
  exec("PRAGMA synchronous=FULL");
  exec(
      "CREATE TABLE IF NOT EXISTS jobs ("
      " seq INTEGER PRIMARY KEY AUTOINCREMENT,"
      " id TEXT NOT NULL UNIQUE,"
      " state TEXT NOT NULL,"
      " scene TEXT NOT NULL,"
      " idempotency_key TEXT UNIQUE,"
      " created_at REAL NOT NULL, started_at REAL NOT NULL DEFAULT 0, finished_at REAL NOT NULL DEFAULT 0,"
      " attempts INTEGER NOT NULL DEFAULT 0,"
      " width INTEGER NOT NULL DEFAULT 0, height INTEGER NOT NULL DEFAULT 0, spp INTEGER NOT NULL DEFAULT 0,"
      " samples_total INTEGER NOT NULL DEFAULT 0,"
      " stats TEXT NOT NULL DEFAULT '', error TEXT NOT NULL DEFAULT '', warnings TEXT NOT NULL DEFAULT '')");
  exec("CREATE INDEX IF NOT EXISTS jobs_by_state ON jobs(state, seq)");
}

JobStore::~JobStore() { sqlite3_close(db_); }

void JobStore::exec(const char* sql) {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string msg = err ? err : "unknown error";
    sqlite3_free(err);
    throw StoreError(std::string("sqlite: ") + msg);
  }
}

JobStore::InsertResult JobStore::insert(const JobRecord& r, const std::string& scene_json) {
  std::lock_guard lock(mutex_);
  InsertResult out;
  if (!r.idempotency_key.empty()) {
    Statement q(db_, (std::string("SELECT ") + kColumns + ", scene FROM jobs WHERE idempotency_key = ?").c_str());
    q.bind(1, r.idempotency_key);
    if (q.step()) {
      out.record = read_record(q);
      out.created = false;
      out.same_scene = q.text(15) == scene_json;
      return out;
    }
  }
  Statement s(db_,
              "INSERT INTO jobs (id, state, scene, idempotency_key, created_at, width, height, spp, "
              "samples_total, warnings) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  s.bind(1, r.id).bind(2, std::string(to_string(JobState::kQueued))).bind(3, scene_json);
  if (r.idempotency_key.empty()) s.bind_null(4);
  else s.bind(4, r.idempotency_key);
  s.bind(5, r.created_at).bind(6, int64_t(r.width)).bind(7, int64_t(r.height)).bind(8, int64_t(r.spp));
  s.bind(9, int64_t(r.samples_total)).bind(10, r.warnings_json);
  s.step();
  out.record = r;
  out.record.state = JobState::kQueued;
  out.record.seq = sqlite3_last_insert_rowid(db_);
  out.created = true;
  return out;
}

std::optional<JobStore::KeyMatch> JobStore::find_by_idempotency_key(const std::string& key,
                                                                    const std::string& scene_json) {
  std::lock_guard lock(mutex_);
  Statement q(db_, (std::string("SELECT ") + kColumns + ", scene FROM jobs WHERE idempotency_key = ?").c_str());
  q.bind(1, key);
  if (!q.step()) return std::nullopt;
  return KeyMatch{read_record(q), q.text(15) == scene_json};
}

std::optional<JobRecord> JobStore::get(const std::string& id) {
  std::lock_guard lock(mutex_);
  Statement q(db_, (std::string("SELECT ") + kColumns + " FROM jobs WHERE id = ?").c_str());
  q.bind(1, id);
  if (!q.step()) return std::nullopt;
  return read_record(q);
}

std::optional<std::string> JobStore::scene(const std::string& id) {
  std::lock_guard lock(mutex_);
  Statement q(db_, "SELECT scene FROM jobs WHERE id = ?");
  q.bind(1, id);
  if (!q.step()) return std::nullopt;
  return q.text(0);
}

std::vector<JobRecord> JobStore::list(std::optional<JobState> state, int64_t before_seq, int limit) {
  std::lock_guard lock(mutex_);
  std::string sql = std::string("SELECT ") + kColumns + " FROM jobs WHERE seq < ? AND " +
                    (state ? "state = ?" : "state != 'deleted'") + " ORDER BY seq DESC LIMIT ?";
  Statement q(db_, sql.c_str());
  int i = 1;
  q.bind(i++, before_seq > 0 ? before_seq : INT64_MAX);
  if (state) q.bind(i++, std::string(to_string(*state)));
  q.bind(i++, int64_t(limit));
  std::vector<JobRecord> out;
  while (q.step()) out.push_back(read_record(q));
  return out;
}

void JobStore::mark_running(const std::string& id, double now) {
  std::lock_guard lock(mutex_);
  Statement s(db_, "UPDATE jobs SET state = 'running', started_at = ?, attempts = attempts + 1 WHERE id = ?");
  s.bind(1, now).bind(2, id).step();
}

void JobStore::mark_finished(const std::string& id, JobState state, double now,
                             const std::string& stats_json, const std::string& error_json) {
  std::lock_guard lock(mutex_);
  Statement s(db_, "UPDATE jobs SET state = ?, finished_at = ?, stats = ?, error = ? WHERE id = ?");
  s.bind(1, std::string(to_string(state))).bind(2, now).bind(3, stats_json).bind(4, error_json).bind(5, id);
  s.step();
}

void JobStore::requeue(const std::string& id) {
  std::lock_guard lock(mutex_);
  Statement s(db_,
              "UPDATE jobs SET state = 'queued', started_at = 0, attempts = MAX(attempts - 1, 0) "
              "WHERE id = ? AND state = 'running'");
  s.bind(1, id).step();
}

void JobStore::mark_deleted(const std::string& id, double now) {
  std::lock_guard lock(mutex_);
  // The scene text goes (it can be megabytes) and the idempotency key is freed for reuse.
  Statement s(db_,
              "UPDATE jobs SET state = 'deleted', finished_at = ?, scene = '', idempotency_key = NULL, "
              "stats = '', error = '', warnings = '' WHERE id = ?");
  s.bind(1, now).bind(2, id).step();
}

std::vector<JobRecord> JobStore::recover() {
  std::lock_guard lock(mutex_);
  exec("UPDATE jobs SET state = 'queued', started_at = 0 WHERE state = 'running'");
  Statement q(db_, (std::string("SELECT ") + kColumns + " FROM jobs WHERE state = 'queued' ORDER BY seq").c_str());
  std::vector<JobRecord> out;
  while (q.step()) out.push_back(read_record(q));
  return out;
}

std::vector<std::string> JobStore::expire(double finished_before) {
  std::lock_guard lock(mutex_);
  std::vector<std::string> ids;
  {
    Statement q(db_,
                "SELECT id FROM jobs WHERE state IN ('succeeded','failed','cancelled','deleted') "
                "AND finished_at < ?");
    q.bind(1, finished_before);
    while (q.step()) ids.push_back(q.text(0));
  }
  Statement d(db_,
              "DELETE FROM jobs WHERE state IN ('succeeded','failed','cancelled','deleted') "
              "AND finished_at < ?");
  d.bind(1, finished_before).step();
  return ids;
}

std::map<JobState, int64_t> JobStore::count_by_state() {
  std::lock_guard lock(mutex_);
  std::map<JobState, int64_t> out;
  Statement q(db_, "SELECT state, COUNT(*) FROM jobs GROUP BY state");
  while (q.step())
    if (auto st = job_state_from_string(q.text(0))) out[*st] = q.integer(1);
  return out;
}

}  // namespace penumbra::server
