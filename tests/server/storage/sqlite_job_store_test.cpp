// The SQLite job store against a temporary file: every field round-trips, updates and
// tombstones, atomic batches, the sequence high-water mark, and what survives reopening.
#include "server/storage/sqlite_job_store.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include "tests/server/test_support.h"

namespace penumbra::test {
namespace {

using server::EraseJob;
using server::InsertJob;
using server::JobRecord;
using server::JobState;
using server::SqliteJobStore;
using server::UpdateJob;

JobRecord record(int seq, const std::string& key = "") {
  JobRecord r;
  r.id = std::string(20, 'a') + std::to_string(1000 + seq);
  r.seq = seq;
  r.idempotency_key = key;
  r.created_at = 1700000000.25 + seq;
  r.width = 32;
  r.height = 16;
  r.spp = 4;
  r.samples_total = 32 * 16 * 4;
  r.warnings_json = R"([{"pointer":"/objects/0","detail":"w"}])";
  return r;
}

void expect_same(const JobRecord& a, const JobRecord& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.seq, b.seq);
  EXPECT_EQ(a.state, b.state);
  EXPECT_EQ(a.idempotency_key, b.idempotency_key);
  EXPECT_EQ(a.created_at, b.created_at);
  EXPECT_EQ(a.started_at, b.started_at);
  EXPECT_EQ(a.finished_at, b.finished_at);
  EXPECT_EQ(a.attempts, b.attempts);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.spp, b.spp);
  EXPECT_EQ(a.samples_total, b.samples_total);
  EXPECT_EQ(a.stats_json, b.stats_json);
  EXPECT_EQ(a.error_json, b.error_json);
  EXPECT_EQ(a.warnings_json, b.warnings_json);
  EXPECT_EQ(a.frame_first, b.frame_first);
  EXPECT_EQ(a.frame_last, b.frame_last);
  EXPECT_EQ(a.frames_done, b.frames_done);
}

TEST(SqliteJobStore, EveryFieldSurvivesReopening) {
  TempDir dir;
  JobRecord r = record(1, "key-1");
  {
    SqliteJobStore store(dir.path() + "/jobs.db");
    store.apply({InsertJob{r, "{\"scene\": 1}"}});
    r.state = JobState::kSucceeded;
    r.started_at = r.created_at + 1;
    r.finished_at = r.created_at + 2.5;
    r.attempts = 2;
    r.stats_json = R"({"seconds":1.5})";
    r.error_json = R"({"detail":"x"})";
    store.apply({UpdateJob{r}});
  }
  SqliteJobStore store(dir.path() + "/jobs.db");
  const server::StoredJobs loaded = store.load();
  ASSERT_EQ(loaded.records.size(), 1u);
  expect_same(loaded.records[0], r);
  EXPECT_EQ(store.scene(r.id), "{\"scene\": 1}");
  EXPECT_EQ(loaded.last_seq, 1);
}

TEST(SqliteJobStore, ATombstoneDropsTheSceneAndFreesTheKey) {
  TempDir dir;
  SqliteJobStore store(dir.path() + "/jobs.db");
  JobRecord r = record(1, "k");
  store.apply({InsertJob{r, "{}"}});
  // The key is unique while its job lives.
  EXPECT_THROW(store.apply({InsertJob{record(2, "k"), "{}"}}), server::StoreError);
  r.state = JobState::kDeleted;
  r.idempotency_key.clear();
  store.apply({UpdateJob{r}});
  EXPECT_FALSE(store.scene(r.id));
  EXPECT_NO_THROW(store.apply({InsertJob{record(2, "k"), "{}"}}));
  ASSERT_EQ(store.load().records.size(), 2u);
}

TEST(SqliteJobStore, ABatchIsAllOrNothing) {
  TempDir dir;
  SqliteJobStore store(dir.path() + "/jobs.db");
  const JobRecord a = record(1), b = record(2);
  JobRecord same_id_as_a = record(3);
  same_id_as_a.id = a.id;
  EXPECT_THROW(store.apply({InsertJob{a, "{}"}, InsertJob{b, "{}"}, InsertJob{same_id_as_a, "{}"}}),
               server::StoreError);
  EXPECT_TRUE(store.load().records.empty()) << "the first two inserts were rolled back";
  store.apply({InsertJob{a, "{}"}, InsertJob{b, "{}"}});
  EXPECT_EQ(store.load().records.size(), 2u) << "the store works after a failed batch";
}

TEST(SqliteJobStore, TheLastSequenceNumberOutlivesErasedJobs) {
  TempDir dir;
  {
    SqliteJobStore store(dir.path() + "/jobs.db");
    store.apply(
        {InsertJob{record(1), "{}"}, InsertJob{record(2), "{}"}, InsertJob{record(3), "{}"}});
    store.apply({EraseJob{record(3).id}, EraseJob{record(2).id}});
  }
  SqliteJobStore store(dir.path() + "/jobs.db");
  const server::StoredJobs loaded = store.load();
  ASSERT_EQ(loaded.records.size(), 1u);
  EXPECT_EQ(loaded.last_seq, 3) << "a new job must not reuse seq 3: old page tokens would name it";
  EXPECT_FALSE(store.scene(record(3).id));
}

// An animation's frame range is stored at insert, frames_done by every update: a restart resumes
// from it. A still keeps first 0, last -1.
TEST(SqliteJobStore, AnimationFramesSurviveReopening) {
  TempDir dir;
  JobRecord still = record(1);
  JobRecord anim = record(2);
  anim.frame_first = -3;
  anim.frame_last = 44;
  {
    SqliteJobStore store(dir.path() + "/jobs.db");
    store.apply({InsertJob{still, "{}"}, InsertJob{anim, "{}"}});
    anim.state = JobState::kRunning;
    anim.frames_done = 17;
    store.apply({UpdateJob{anim}});
  }
  SqliteJobStore store(dir.path() + "/jobs.db");
  const server::StoredJobs loaded = store.load();
  ASSERT_EQ(loaded.records.size(), 2u);
  for (const JobRecord& r : loaded.records) expect_same(r, r.id == anim.id ? anim : still);
  for (const JobRecord& r : loaded.records)
    EXPECT_EQ(r.frame_count(), r.id == anim.id ? 48 : 0);
}

// A database of the version before animations (no frame columns) gains them: its jobs are stills.
TEST(SqliteJobStore, AnOlderDatabaseGainsTheFrameColumns) {
  TempDir dir;
  JobRecord r = record(1);
  {
    SqliteJobStore store(dir.path() + "/jobs.db");
    store.apply({InsertJob{r, "{}"}});
  }
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir.path() + "/jobs.db").c_str(), &db), SQLITE_OK);
    for (const char* column : {"frame_first", "frame_last", "frames_done"})
      ASSERT_EQ(sqlite3_exec(db, (std::string("ALTER TABLE jobs DROP COLUMN ") + column).c_str(),
                             nullptr, nullptr, nullptr),
                SQLITE_OK);
    sqlite3_close(db);
  }
  SqliteJobStore store(dir.path() + "/jobs.db");
  const server::StoredJobs loaded = store.load();
  ASSERT_EQ(loaded.records.size(), 1u);
  expect_same(loaded.records[0], r);
  EXPECT_EQ(loaded.records[0].frame_count(), 0);
}

}  // namespace
}  // namespace penumbra::test

namespace penumbra::test {
namespace {

namespace fs = std::filesystem;

TEST(SqliteJobStore, ScenesAreFilesBesideTheDatabase) {
  // Issue 15: 11 jobs of 12 MB scenes made a 138 MB database. Here 8 jobs of 1 MB scenes leave
  // the database (and its WAL) small, the scenes in scenes/<id>.json.
  TempDir dir;
  SqliteJobStore store(dir.path() + "/jobs.db");
  const std::string big = "{\"pad\": \"" + std::string(1 << 20, 'x') + "\"}";
  for (int i = 1; i <= 8; ++i) store.apply({InsertJob{record(i), big}});
  EXPECT_EQ(store.scene(record(3).id), big);
  EXPECT_EQ(fs::file_size(fs::path(dir.path()) / "scenes" / (record(3).id + ".json")), big.size());
  std::uintmax_t db_bytes = fs::file_size(dir.path() + "/jobs.db");
  if (fs::exists(dir.path() + "/jobs.db-wal")) db_bytes += fs::file_size(dir.path() + "/jobs.db-wal");
  EXPECT_LT(db_bytes, 512u << 10);
}

TEST(SqliteJobStore, TombstonesAndErasesRemoveTheSceneFile) {
  TempDir dir;
  SqliteJobStore store(dir.path() + "/jobs.db");
  JobRecord a = record(1), b = record(2);
  store.apply({InsertJob{a, "{}"}, InsertJob{b, "{}"}});
  const fs::path scenes = fs::path(dir.path()) / "scenes";
  ASSERT_TRUE(fs::exists(scenes / (a.id + ".json")));
  a.state = JobState::kDeleted;
  store.apply({UpdateJob{a}, EraseJob{b.id}});
  EXPECT_FALSE(fs::exists(scenes / (a.id + ".json")));
  EXPECT_FALSE(fs::exists(scenes / (b.id + ".json")));
}

TEST(SqliteJobStore, OrphanSceneFilesGoAtLoad) {
  // A crash between the scene file and the commit of its row leaves the file alone.
  TempDir dir;
  SqliteJobStore store(dir.path() + "/jobs.db");
  store.apply({InsertJob{record(1), "{}"}});
  const fs::path orphan = fs::path(dir.path()) / "scenes" / "ffffffffffffffffffffffff.json";
  std::ofstream(orphan) << "{}";
  store.load();
  EXPECT_FALSE(fs::exists(orphan));
  EXPECT_TRUE(fs::exists(fs::path(dir.path()) / "scenes" / (record(1).id + ".json")));
}

}  // namespace
}  // namespace penumbra::test
