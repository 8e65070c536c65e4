#include "server/http/result_response.h"

#include <httplib.h>

#include <algorithm>

#include "server/http/accept_negotiation.h"

namespace penumbra::server {

bool send_result(httplib::Response& res, const JobService& jobs, const std::string& id,
                 ImageFormat format) {
  auto stored = jobs.open_result(id, file_extension(format));
  if (!stored) return false;
  res.set_header("Content-Disposition",
                 std::string("inline; filename=\"") + id + "." + file_extension(format) + "\"");
  res.set_header("ETag", "\"" + id + "-" + file_extension(format) + "\"");
  res.set_header("Cache-Control", "private, max-age=3600");
  res.set_content_provider(
      stored->size, mime_type(format),
      [stream = stored->stream](size_t offset, size_t length, httplib::DataSink& sink) {
        char buf[1 << 16];
        stream->clear();
        stream->seekg(std::streamoff(offset));
        const auto n = std::min(length, sizeof buf);
        stream->read(buf, std::streamsize(n));
        const auto got = stream->gcount();
        if (got <= 0) return false;
        sink.write(buf, size_t(got));
        return true;
      });
  return true;
}

}  // namespace penumbra::server
