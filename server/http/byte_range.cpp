#include "server/http/byte_range.h"

#include <cctype>

#include "server/text_util.h"

namespace penumbra::server {
namespace {

// 1*DIGIT up to 19 digits (below 2^63); nullopt otherwise.
std::optional<std::uint64_t> parse_position(std::string_view s) {
  if (s.empty() || s.size() > 19) return std::nullopt;
  std::uint64_t v = 0;
  for (char c : s) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return std::nullopt;
    v = v * 10 + std::uint64_t(c - '0');
  }
  return v;
}

}  // namespace

RangeDecision decide_range(std::optional<std::string_view> header, std::uint64_t size) {
  using Kind = RangeDecision::Kind;
  if (!header) return {};
  std::string_view h = trim_ows(*header);
  const std::string_view unit = "bytes=";
  if (h.size() < unit.size() || ascii_lower(std::string(h.substr(0, unit.size()))) != unit)
    return {};
  h = trim_ows(h.substr(unit.size()));
  const std::size_t dash = h.find('-');
  if (dash == std::string_view::npos || h.find(',') != std::string_view::npos) return {};
  const std::string_view first_text = h.substr(0, dash);
  const std::string_view last_text = h.substr(dash + 1);
  RangeDecision d;
  if (first_text.empty()) {  // suffix-range: the last N bytes
    const auto suffix = parse_position(last_text);
    if (!suffix) return {};
    if (*suffix == 0 || size == 0) return {Kind::kUnsatisfiable};
    d.kind = Kind::kPartial;
    d.first = *suffix >= size ? 0 : size - *suffix;
    d.last = size - 1;
    return d;
  }
  const auto first = parse_position(first_text);
  if (!first) return {};
  std::optional<std::uint64_t> last;
  if (!last_text.empty()) {
    last = parse_position(last_text);
    if (!last || *last < *first) return {};  // invalid: ignored (section 14.1.1)
  }
  if (*first >= size) return {Kind::kUnsatisfiable};
  d.kind = Kind::kPartial;
  d.first = *first;
  d.last = last && *last < size ? *last : size - 1;
  return d;
}

}  // namespace penumbra::server
