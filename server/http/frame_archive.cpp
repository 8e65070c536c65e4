#include "server/http/frame_archive.h"

#include <algorithm>
#include <istream>

#include "api/animation.h"
#include "server/http/tar_header.h"

namespace penumbra::server {

std::string frame_file_name(int frame, int digits, const std::string& key) {
  return api::frame_path("frame_" + std::string(std::size_t(digits), '#') + "." + key, frame);
}

int frame_digits(int first, int last) {
  const auto digits = [](int v) { return int(std::to_string(v < 0 ? -std::int64_t(v) : v).size()); };
  return std::max({4, digits(first), digits(last)});
}

std::optional<FrameArchive> plan_frame_archive(const JobBackend& jobs, const std::string& id,
                                               const std::string& key,
                                               const std::vector<int>& frames, int digits,
                                               std::int64_t mtime) {
  FrameArchive a;
  a.job = id;
  a.key = key;
  a.mtime = mtime;
  std::uint64_t offset = 0;
  for (const int frame : frames) {
    // Opened for its size only: the stream closes here, one file is open while streaming.
    const auto stored = jobs.open_result(id, key, frame);
    if (!stored || stored->size > kTarMaxFileBytes) return std::nullopt;
    a.entries.push_back({frame, frame_file_name(frame, digits, key), offset, stored->size});
    offset += kTarBlock + tar_padded(stored->size);
  }
  a.size = offset + 2 * kTarBlock;  // the end of an archive: two zero blocks
  return a;
}

bool read_frame_archive(const JobBackend& jobs, const FrameArchive& archive,
                        FrameArchiveCursor& cursor, std::uint64_t offset, std::size_t length,
                        std::string& out) {
  out.clear();
  const std::uint64_t end = std::min<std::uint64_t>(archive.size, offset + length);
  while (offset < end) {
    // The entry holding `offset`: the last whose header starts at or before it.
    const auto it = std::upper_bound(
        archive.entries.begin(), archive.entries.end(), offset,
        [](std::uint64_t o, const FrameArchiveEntry& e) { return o < e.offset; });
    if (it == archive.entries.begin()) {  // no entries at all: only the closing blocks
      out.append(std::size_t(end - offset), '\0');
      return true;
    }
    const FrameArchiveEntry& e = *(it - 1);
    const std::size_t index = std::size_t(it - 1 - archive.entries.begin());
    const std::uint64_t data_start = e.offset + kTarBlock;
    const std::uint64_t data_end = data_start + e.size;
    const std::uint64_t entry_end = data_start + tar_padded(e.size);
    if (offset < data_start) {
      const auto header = tar_file_header(e.name, e.size, archive.mtime);
      const std::size_t n = std::size_t(std::min(end, data_start) - offset);
      out.append(header.data() + (offset - e.offset), n);
      offset += n;
    } else if (offset < data_end) {
      if (cursor.entry != index || !cursor.stream) {
        const auto stored = jobs.open_result(archive.job, archive.key, e.frame);
        if (!stored || stored->size != e.size) return false;
        cursor.entry = index;
        cursor.stream = stored->stream;
      }
      const std::size_t n = std::size_t(std::min(end, data_end) - offset);
      const std::size_t at = out.size();
      out.resize(at + n);
      cursor.stream->clear();
      cursor.stream->seekg(std::streamoff(offset - data_start));
      cursor.stream->read(out.data() + at, std::streamsize(n));
      if (cursor.stream->gcount() != std::streamsize(n)) return false;
      offset += n;
    } else {
      // The padding of the last block of a file, or past the last entry: the closing blocks.
      const std::uint64_t zeros_end = offset < entry_end ? entry_end : archive.size;
      const std::size_t n = std::size_t(std::min(end, zeros_end) - offset);
      out.append(n, '\0');
      offset += n;
    }
  }
  return true;
}

}  // namespace penumbra::server
