#include "server/http/accept_negotiation.h"

#include <algorithm>

#include "server/text_util.h"

namespace penumbra::server {
namespace {

// The format a media range (lower case, no parameters) asks for, if the service makes it.
std::optional<ImageFormat> format_for_range(std::string_view range) {
  if (range == "image/png" || range == "image/*" || range == "*/*") return ImageFormat::kPng;
  if (range == "image/x-exr" || range == "image/exr" || range == "image/aces")
    return ImageFormat::kExr;
  return std::nullopt;
}

// True when the parameters of a media range (";q=0;level=1" ...) include q=0.
bool refused(std::string_view params) {
  while (!params.empty()) {
    const std::size_t semi = std::min(params.find(';'), params.size());
    const std::string_view param = params.substr(0, semi);
    params.remove_prefix(std::min(semi + 1, params.size()));
    const std::size_t eq = param.find('=');
    if (eq == std::string_view::npos) continue;
    if (trim_ows(param.substr(0, eq)) == "q" && is_zero_qvalue(trim_ows(param.substr(eq + 1))))
      return true;
  }
  return false;
}

}  // namespace

bool is_zero_qvalue(std::string_view v) {
  if (v.empty() || v.front() != '0') return false;
  if (v.size() == 1) return true;
  return v[1] == '.' && std::all_of(v.begin() + 2, v.end(), [](char c) { return c == '0'; });
}

std::variant<ImageFormat, Problem> negotiate_image_format(
    const std::optional<std::string>& format_param,
    const std::optional<std::string>& accept_header) {
  if (format_param) {
    const std::string f = ascii_lower(*format_param);
    if (f == "png") return ImageFormat::kPng;
    if (f == "exr") return ImageFormat::kExr;
    return invalid_parameter("format", "must be png or exr");
  }
  if (!accept_header) return ImageFormat::kPng;
  const std::string accept = ascii_lower(*accept_header);
  std::string_view rest = accept;
  // Bounded as well as linear: only the first kMaxMediaRanges ranges are read (the header line
  // itself is capped at 8 KiB by ConnectionStream).
  std::size_t ranges = 0;
  while (!rest.empty() && ranges++ < kMaxMediaRanges) {
    const std::size_t comma = std::min(rest.find(','), rest.size());
    std::string_view range = rest.substr(0, comma);
    rest.remove_prefix(std::min(comma + 1, rest.size()));
    std::string_view params;
    if (const std::size_t semi = range.find(';'); semi != std::string_view::npos) {
      params = range.substr(semi + 1);
      range = range.substr(0, semi);
    }
    if (refused(params)) continue;
    if (const auto format = format_for_range(trim_ows(range))) return *format;
  }
  return make_problem(406, "not-acceptable", "Not Acceptable",
                      "results are image/png or image/x-exr (or use ?format=png|exr); only the "
                      "first " + std::to_string(kMaxMediaRanges) + " media ranges of Accept are read");
}

const char* mime_type(ImageFormat f) {
  return f == ImageFormat::kPng ? "image/png" : "image/x-exr";
}
const char* file_extension(ImageFormat f) { return f == ImageFormat::kPng ? "png" : "exr"; }

}  // namespace penumbra::server
