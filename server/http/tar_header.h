#pragma once
// One POSIX ustar header block (IEEE Std 1003.1-2001, "pax" interchange format, ustar header):
// enough for an archive of regular files with short names, which every tar reads. Written here
// rather than through libarchive: the archive is streamed from files on disk at offsets the
// HTTP layer chooses (Range requests), so its exact layout and size must be known up front,
// and the header is 512 bytes of fixed fields.
#include <array>
#include <cstdint>
#include <string>

namespace penumbra::server {

inline constexpr std::uint64_t kTarBlock = 512;
// ustar's size field holds 11 octal digits: files below 8 GiB.
inline constexpr std::uint64_t kTarMaxFileBytes = (std::uint64_t(1) << 33) - 1;

// The header of a regular file `name` (at most 100 bytes, no directory) of `size` bytes, mode
// 0644, modified at `mtime` (Unix seconds). Throws std::invalid_argument beyond those bounds.
std::array<char, kTarBlock> tar_file_header(const std::string& name, std::uint64_t size,
                                            std::int64_t mtime);
// A file's bytes in the archive: the data rounded up to whole blocks.
inline std::uint64_t tar_padded(std::uint64_t size) {
  return (size + kTarBlock - 1) / kTarBlock * kTarBlock;
}

}  // namespace penumbra::server
