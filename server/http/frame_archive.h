#pragma once
// GET /v1/jobs/{id}/frames.tar: every finished frame of an animation job in one ustar archive
// (frame_0001.exr, frame_0002.exr, ...), streamed from the stored frames a block at a time:
// nothing is built in memory, so 1000 frames cost one open file at a time. The layout (each
// frame's header offset and size) is fixed before the first byte is sent, so the answer has a
// Content-Length and serves a Range (a download of many gigabytes can resume).
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "server/jobs/job_backend.h"

namespace penumbra::server {

struct FrameArchiveEntry {
  int frame = 0;
  std::string name;          // in the archive: frame_0017.exr
  std::uint64_t offset = 0;  // of its header block in the archive
  std::uint64_t size = 0;    // of its data
};

struct FrameArchive {
  std::string job;
  std::string key;  // the result key of every frame ("exr", "albedo.png", "blender.exr")
  std::int64_t mtime = 0;
  std::vector<FrameArchiveEntry> entries;
  std::uint64_t size = 0;  // of the whole archive, with its two closing zero blocks
};

// The file name of frame `frame` in the archive: "frame_" + the number zero-padded to `digits`
// + "." + the key ("frame_0017.exr", "frame_0017.albedo.png").
std::string frame_file_name(int frame, int digits, const std::string& key);
// Digits for the frame numbers of [first, last]: 4 (Blender's ####) or more if they need it.
int frame_digits(int first, int last);

// Sizes every frame of `frames` (their stored results under `key`); nullopt when one is missing.
std::optional<FrameArchive> plan_frame_archive(const JobBackend& jobs, const std::string& id,
                                               const std::string& key,
                                               const std::vector<int>& frames, int digits,
                                               std::int64_t mtime);

// Copies up to `length` bytes of the archive from `offset` into `out` (cleared first); reading
// a frame's file as needed, and keeping it open in `cursor` for the next call. False when a
// frame's file is gone or no longer the planned size (the job was deleted meanwhile).
struct FrameArchiveCursor {
  std::size_t entry = SIZE_MAX;  // the entry whose file is open
  std::shared_ptr<std::istream> stream;
};
bool read_frame_archive(const JobBackend& jobs, const FrameArchive& archive,
                        FrameArchiveCursor& cursor, std::uint64_t offset, std::size_t length,
                        std::string& out);

}  // namespace penumbra::server
