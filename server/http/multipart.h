#pragma once
// A small, bounded multipart/form-data parser (RFC 7578 over RFC 2046) for the one-shot job
// form `curl -F scene=@scene.json -F bunny.ply=@bunny.ply .../v1/jobs`. cpp-httplib's own
// parser is not used: it runs before any handler, on a body of any size, with no cap on parts
// or part headers (../shared/ARCHITECTURE.md). Here the body has already been read within its
// Content-Length limit; parts are views into it (no copy), and the number of parts, the size of
// each part's head and the number of its header lines are capped. Every error says what is
// wrong, for a 400.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra::server {

struct MultipartPart {
  std::string name;      // Content-Disposition: form-data; name="..."
  std::string filename;  // filename="..." when given (curl -F name=@file sends it)
  std::string content_type;
  std::string_view data;  // into the body
};

struct MultipartLimits {
  std::size_t max_parts = 1001;
  std::size_t max_part_head_bytes = 8192;
  std::size_t max_part_headers = 16;
};

struct MultipartResult {
  std::vector<MultipartPart> parts;
  std::string error;  // empty on success
};

// The boundary parameter of a multipart/form-data Content-Type (1 to 70 characters, RFC 2046
// section 5.1.1), or nullopt.
std::optional<std::string> multipart_boundary(std::string_view content_type);

MultipartResult parse_multipart(std::string_view body, std::string_view boundary,
                                const MultipartLimits& limits);

}  // namespace penumbra::server
