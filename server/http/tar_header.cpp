#include "server/http/tar_header.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace penumbra::server {
namespace {

// A numeric field: octal digits, zero-padded to width - 1, then NUL (the caller keeps the value
// within width - 1 digits: tar_file_header checks the size).
void put_octal(char* field, std::size_t width, std::uint64_t value) {
  field[width - 1] = '\0';
  for (std::size_t i = width - 1; i-- > 0; value >>= 3) field[i] = char('0' + (value & 7));
}

}  // namespace

std::array<char, kTarBlock> tar_file_header(const std::string& name, std::uint64_t size,
                                            std::int64_t mtime) {
  if (name.empty() || name.size() > 100 || name.find('/') != std::string::npos)
    throw std::invalid_argument("tar: bad file name " + name);
  if (size > kTarMaxFileBytes) throw std::invalid_argument("tar: file too large: " + name);
  std::array<char, kTarBlock> h{};
  // Field offsets and widths of the ustar header.
  std::memcpy(h.data() + 0, name.data(), name.size());  // name[100]
  put_octal(h.data() + 100, 8, 0644);                    // mode
  put_octal(h.data() + 108, 8, 0);                       // uid
  put_octal(h.data() + 116, 8, 0);                       // gid
  put_octal(h.data() + 124, 12, size);                   // size
  // mtime: 11 octal digits reach the year 4147.
  put_octal(h.data() + 136, 12, std::uint64_t(std::clamp<std::int64_t>(mtime, 0, 077777777777)));
  h[156] = '0';                                          // typeflag: regular file
  std::memcpy(h.data() + 257, "ustar", 6);               // magic "ustar\0"
  std::memcpy(h.data() + 263, "00", 2);                  // version
  // The checksum: the sum of the header's bytes (unsigned) with its own field as 8 spaces,
  // written as 6 octal digits, NUL, space.
  std::memset(h.data() + 148, ' ', 8);
  unsigned sum = 0;
  for (const char c : h) sum += static_cast<unsigned char>(c);
  put_octal(h.data() + 148, 7, sum);  // 6 digits, NUL
  h[155] = ' ';
  return h;
}

}  // namespace penumbra::server
