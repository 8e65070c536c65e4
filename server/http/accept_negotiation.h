#pragma once
// Which image format a result request wants: ?format=png|exr wins; else the first media range
// of Accept (RFC 9110 section 12.5.1) the service makes and the client did not refuse with
// q=0; else PNG. Plain string parsing, no std::regex: this runs on every result request.
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "renderer/io/image_io.h"
#include "server/http/problem.h"

namespace penumbra::server {

// Media ranges of Accept looked at; later ones are ignored.
inline constexpr std::size_t kMaxMediaRanges = 64;

// format_param: the ?format= value if present; accept: the Accept header if present.
// A Problem is 400 (bad format value) or 406 (Accept names nothing the service makes).
std::variant<ImageFormat, Problem> negotiate_image_format(
    const std::optional<std::string>& format_param, const std::optional<std::string>& accept);

// True for a qvalue of zero: "0", "0.", "0.0" ... (RFC 9110 section 12.4.2).
bool is_zero_qvalue(std::string_view value);

const char* mime_type(ImageFormat format);
const char* file_extension(ImageFormat format);

}  // namespace penumbra::server
