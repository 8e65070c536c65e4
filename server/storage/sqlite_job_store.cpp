#include "server/storage/sqlite_job_store.h"

#include <fcntl.h>
#include <sqlite3.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <nlohmann/json.hpp>
#include <sstream>

namespace penumbra::server {
namespace {

// One prepared statement, finalised on every path out.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK)
      throw StoreError(std::string("sqlite prepare: ") + sqlite3_errmsg(db));
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, const std::string& v) {
    return check(sqlite3_bind_text(stmt_, i, v.data(), int(v.size()), SQLITE_TRANSIENT));
  }
  Statement& bind(int i, int64_t v) { return check(sqlite3_bind_int64(stmt_, i, v)); }
  Statement& bind(int i, double v) { return check(sqlite3_bind_double(stmt_, i, v)); }
  // "" is stored as NULL: the UNIQUE idempotency_key column admits many NULLs, not many "".
  Statement& bind_or_null(int i, const std::string& v) {
    return v.empty() ? check(sqlite3_bind_null(stmt_, i)) : bind(i, v);
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
  Statement& check(int rc) {
    if (rc != SQLITE_OK) throw StoreError(std::string("sqlite bind: ") + sqlite3_errmsg(db_));
    return *this;
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

constexpr const char* kColumns =
    "id, seq, state, idempotency_key, created_at, started_at, finished_at, attempts, width, "
    "height, "
    "spp, samples_total, stats, error, warnings, priority, notify, frame_first, frame_last, "
    "frames_done";

// The webhook of a job (JobRecord::Notify) as the text of the notify column; "" when none.
std::string notify_text(const JobRecord::Notify& n) {
  if (n.url.empty()) return "";
  return nlohmann::json{{"url", n.url},
                        {"secret", n.secret},
                        {"attempts", n.attempts},
                        {"last_status", n.last_status},
                        {"last_error", n.last_error},
                        {"last_attempt_at", n.last_attempt_at},
                        {"next_attempt_at", n.next_attempt_at},
                        {"delivered_at", n.delivered_at},
                        {"gave_up_at", n.gave_up_at}}
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

JobRecord::Notify notify_from_text(const std::string& text) {
  JobRecord::Notify n;
  if (text.empty()) return n;
  const auto j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) return n;
  n.url = j.value("url", "");
  n.secret = j.value("secret", "");
  n.attempts = j.value("attempts", 0);
  n.last_status = j.value("last_status", 0);
  n.last_error = j.value("last_error", "");
  n.last_attempt_at = j.value("last_attempt_at", 0.0);
  n.next_attempt_at = j.value("next_attempt_at", 0.0);
  n.delivered_at = j.value("delivered_at", 0.0);
  n.gave_up_at = j.value("gave_up_at", 0.0);
  return n;
}

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
  r.priority = int(s.integer(15));
  r.notify = notify_from_text(s.text(16));
  r.frame_first = int(s.integer(17));
  r.frame_last = int(s.integer(18));
  r.frames_done = int(s.integer(19));
  return r;
}

}  // namespace

SqliteJobStore::SqliteJobStore(const std::string& path)
    : scenes_dir_((std::filesystem::path(path).parent_path() / "scenes").string()) {
  std::error_code ec;
  std::filesystem::create_directories(scenes_dir_, ec);
  if (ec) throw StoreError("cannot create " + scenes_dir_ + ": " + ec.message());
  if (sqlite3_open_v2(path.c_str(), &db_,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
                      nullptr) != SQLITE_OK) {
    const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw StoreError("cannot open " + path + ": " + msg);
  }
  sqlite3_busy_timeout(db_, 5000);
  // WAL: readers never wait for the writer. synchronous=FULL: a commit is on disk when it
  // returns (https://www.sqlite.org/pragma.html#pragma_synchronous), so even a power cut
  // cannot lose an accepted job.
  exec("PRAGMA journal_mode=WAL");
  exec("PRAGMA synchronous=FULL");
  exec(
      "CREATE TABLE IF NOT EXISTS jobs ("
      " seq INTEGER PRIMARY KEY AUTOINCREMENT,"
      " id TEXT NOT NULL UNIQUE,"
      " state TEXT NOT NULL,"
      " scene TEXT NOT NULL,"
      " idempotency_key TEXT UNIQUE,"
      " created_at REAL NOT NULL, started_at REAL NOT NULL DEFAULT 0, finished_at REAL NOT NULL "
      "DEFAULT 0,"
      " attempts INTEGER NOT NULL DEFAULT 0,"
      " width INTEGER NOT NULL DEFAULT 0, height INTEGER NOT NULL DEFAULT 0, spp INTEGER NOT NULL "
      "DEFAULT 0,"
      " samples_total INTEGER NOT NULL DEFAULT 0,"
      " stats TEXT NOT NULL DEFAULT '', error TEXT NOT NULL DEFAULT '', warnings TEXT NOT NULL "
      "DEFAULT '')");
  exec("CREATE INDEX IF NOT EXISTS jobs_by_state ON jobs(state, seq)");
  // Columns added after the first schema: a data directory of an older version gains them with
  // their defaults (every old job has priority 0 and no webhook).
  add_column_if_missing("priority", "INTEGER NOT NULL DEFAULT 0");
  add_column_if_missing("notify", "TEXT NOT NULL DEFAULT ''");
  // Animations (docs/animation-and-windows.md): a still is first 0, last -1 (no frames).
  add_column_if_missing("frame_first", "INTEGER NOT NULL DEFAULT 0");
  add_column_if_missing("frame_last", "INTEGER NOT NULL DEFAULT -1");
  add_column_if_missing("frames_done", "INTEGER NOT NULL DEFAULT 0");
}

void SqliteJobStore::add_column_if_missing(const std::string& name, const std::string& decl) {
  Statement q(db_, "SELECT 1 FROM pragma_table_info('jobs') WHERE name = ?");
  q.bind(1, name);
  if (q.step()) return;
  exec(("ALTER TABLE jobs ADD COLUMN " + name + " " + decl).c_str());
}

SqliteJobStore::~SqliteJobStore() { sqlite3_close(db_); }

void SqliteJobStore::exec(const char* sql) {
  char* err = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string msg = err ? err : "unknown error";
    sqlite3_free(err);
    throw StoreError(std::string("sqlite: ") + msg);
  }
}

StoredJobs SqliteJobStore::load() {
  std::lock_guard lock(mutex_);
  StoredJobs out;
  Statement q(db_, std::string("SELECT ") + kColumns + " FROM jobs");
  while (q.step()) out.records.push_back(read_record(q));
  // AUTOINCREMENT remembers the highest seq in sqlite_sequence, also after that row is deleted.
  Statement last(db_,
                 "SELECT MAX(n) FROM (SELECT seq AS n FROM sqlite_sequence WHERE name = 'jobs' "
                 "UNION ALL SELECT MAX(seq) FROM jobs)");
  if (last.step()) out.last_seq = last.integer(0);
  remove_orphan_scenes(out.records);
  return out;
}

std::string SqliteJobStore::scene_path(const std::string& id) const {
  return (std::filesystem::path(scenes_dir_) / (id + ".json")).string();
}

void SqliteJobStore::write_scene(const std::string& id, const std::string& scene_json) const {
  // Whole or not at all, and on disk before the row that names it commits.
  const std::string final_path = scene_path(id);
  const std::string tmp = final_path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw StoreError("cannot create " + tmp + ": " + std::strerror(errno));
  std::size_t done = 0;
  while (done < scene_json.size()) {
    const ssize_t n = ::write(fd, scene_json.data() + done, scene_json.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string err = std::strerror(errno);
      ::close(fd);
      ::unlink(tmp.c_str());
      throw StoreError("cannot write " + tmp + ": " + err);
    }
    done += std::size_t(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0 || ::rename(tmp.c_str(), final_path.c_str()) != 0) {
    const std::string err = std::strerror(errno);
    ::unlink(tmp.c_str());
    throw StoreError("cannot store " + final_path + ": " + err);
  }
  const int dir = ::open(scenes_dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

void SqliteJobStore::remove_orphan_scenes(const std::vector<JobRecord>& records) const {
  std::set<std::string> live;
  for (const JobRecord& r : records)
    if (r.state != JobState::kDeleted) live.insert(r.id + ".json");
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(scenes_dir_, ec)) {
    const std::string name = entry.path().filename().string();
    if (!live.count(name)) std::filesystem::remove(entry.path(), ec);
  }
}

std::optional<std::string> SqliteJobStore::scene(const std::string& id) {
  {
    std::lock_guard lock(mutex_);
    Statement q(db_, "SELECT scene FROM jobs WHERE id = ? AND state != 'deleted'");
    q.bind(1, id);
    if (!q.step()) return std::nullopt;
    std::string in_row = q.text(0);
    if (!in_row.empty()) return in_row;  // a row written by an earlier version
  }
  std::ifstream in(scene_path(id), std::ios::binary);
  if (!in) throw StoreError("the scene file of job " + id + " is missing");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void SqliteJobStore::apply(const std::vector<JobChange>& changes) {
  if (changes.empty()) return;
  std::lock_guard lock(mutex_);
  // One transaction, so one fsync for the whole batch (group commit).
  std::vector<std::string> remove_after_commit;
  exec("BEGIN IMMEDIATE");
  try {
    for (const JobChange& c : changes) apply_one(c, remove_after_commit);
    exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);  // the error being thrown says why
    throw;
  }
  std::error_code ec;
  for (const std::string& file : remove_after_commit) std::filesystem::remove(file, ec);
}

void SqliteJobStore::apply_one(const JobChange& change,
                               std::vector<std::string>& remove_after_commit) {
  if (const auto* insert = std::get_if<InsertJob>(&change)) {
    const JobRecord& r = insert->record;
    write_scene(r.id, insert->scene_json);  // the row keeps '' in its scene column
    Statement s(db_,
                "INSERT INTO jobs (seq, id, state, scene, idempotency_key, created_at, started_at, "
                "finished_at, attempts, width, height, spp, samples_total, stats, error, warnings, "
                "priority, notify, frame_first, frame_last, frames_done) "
                "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    s.bind(1, r.seq)
        .bind(2, r.id)
        .bind(3, std::string(to_string(r.state)))
        .bind(4, std::string());
    s.bind_or_null(5, r.idempotency_key)
        .bind(6, r.created_at)
        .bind(7, r.started_at)
        .bind(8, r.finished_at);
    s.bind(9, int64_t(r.attempts)).bind(10, int64_t(r.width)).bind(11, int64_t(r.height));
    s.bind(12, int64_t(r.spp)).bind(13, int64_t(r.samples_total)).bind(14, r.stats_json);
    s.bind(15, r.error_json).bind(16, r.warnings_json);
    s.bind(17, int64_t(r.priority)).bind(18, notify_text(r.notify));
    s.bind(19, int64_t(r.frame_first)).bind(20, int64_t(r.frame_last));
    s.bind(21, int64_t(r.frames_done));
    s.step();
  } else if (const auto* update = std::get_if<UpdateJob>(&change)) {
    const JobRecord& r = update->record;
    // A tombstone's scene goes: it can be megabytes and nothing reads it again.
    Statement s(
        db_,
        "UPDATE jobs SET state = ?1, idempotency_key = ?2, started_at = ?3, finished_at = ?4, "
        "attempts = ?5, samples_total = ?6, stats = ?7, error = ?8, warnings = ?9, "
        "scene = CASE WHEN ?1 = 'deleted' THEN '' ELSE scene END, priority = ?11, notify = ?12, "
        "frames_done = ?13 "
        "WHERE id = ?10");
    s.bind(1, std::string(to_string(r.state)))
        .bind_or_null(2, r.idempotency_key)
        .bind(3, r.started_at);
    s.bind(4, r.finished_at).bind(5, int64_t(r.attempts)).bind(6, int64_t(r.samples_total));
    s.bind(7, r.stats_json).bind(8, r.error_json).bind(9, r.warnings_json).bind(10, r.id);
    s.bind(11, int64_t(r.priority)).bind(12, notify_text(r.notify));
    s.bind(13, int64_t(r.frames_done));
    s.step();
    if (r.state == JobState::kDeleted) remove_after_commit.push_back(scene_path(r.id));
  } else {
    const std::string& id = std::get<EraseJob>(change).id;
    Statement s(db_, "DELETE FROM jobs WHERE id = ?");
    s.bind(1, id);
    s.step();
    remove_after_commit.push_back(scene_path(id));
  }
}

}  // namespace penumbra::server
