// libFuzzer target for the request-head checks that run before cpp-httplib parses anything:
// every line through check_head_line (server/http/header_line_check.h), and the input as a Range
// header through decide_range (server/http/byte_range.h) against several file sizes. A partial
// range must lie inside the file.
#include <cstdint>
#include <string_view>

#include "server/http/byte_range.h"
#include "server/http/header_line_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace penumbra::server;
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  const ConnectionLimits limits;
  std::size_t start = 0;
  for (std::size_t index = 0; index < 256 && start <= in.size(); ++index) {
    const std::size_t nl = in.find('\n', start);
    const std::string_view line =
        in.substr(start, nl == std::string_view::npos ? std::string_view::npos : nl - start);
    if (const auto p = check_head_line(line, index, limits)) {
      if (p->status < 400 || p->status > 431) __builtin_trap();
    }
    if (nl == std::string_view::npos) break;
    start = nl + 1;
  }
  for (const std::uint64_t file_size :
       {std::uint64_t(0), std::uint64_t(1), std::uint64_t(1000), std::uint64_t(1) << 62}) {
    const RangeDecision d = decide_range(in, file_size);
    if (d.kind == RangeDecision::Kind::kPartial && !(d.first <= d.last && d.last < file_size))
      __builtin_trap();
  }
  return 0;
}
