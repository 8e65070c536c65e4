#pragma once
// The one byte range of a Range header against a representation of `size` bytes, by RFC 9110
// section 14: a range starting at or past the end, a zero-length suffix (bytes=-0), or any range
// of an empty file is unsatisfiable (416 with Content-Range: bytes */size); a last position past
// the end is cut to the end; a suffix longer than the file means the whole file. A header of
// another unit, or one this parser does not read, is ignored (section 14.2 allows it): the whole
// representation is sent. Several ranges are refused before this (request_guard).
#include <cstdint>
#include <optional>
#include <string_view>

namespace penumbra::server {

struct RangeDecision {
  enum class Kind { kWhole, kPartial, kUnsatisfiable };
  Kind kind = Kind::kWhole;
  std::uint64_t first = 0;  // inclusive, for kPartial
  std::uint64_t last = 0;   // inclusive, for kPartial
};

RangeDecision decide_range(std::optional<std::string_view> header, std::uint64_t size);

}  // namespace penumbra::server
