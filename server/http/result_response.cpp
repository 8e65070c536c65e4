#include "server/http/result_response.h"

#include <httplib.h>

#include <algorithm>

#include "server/http/accept_negotiation.h"
#include "server/http/byte_range.h"
#include "server/http/job_json.h"
#include "server/http/problem.h"

namespace penumbra::server {

bool send_result(httplib::Response& res, const JobBackend& jobs, const std::string& id,
                 ImageFormat format, const std::optional<std::string>& range,
                 const std::string& variant) {
  const std::string key = variant.empty() ? std::string(file_extension(format))
                                          : variant + "." + file_extension(format);
  auto stored = jobs.open_result(id, key, std::nullopt);
  if (!stored) return false;
  const std::uint64_t size = stored->size;
  std::string tag = key;
  std::replace(tag.begin(), tag.end(), '.', '-');
  res.set_header("Content-Disposition", std::string("inline; filename=\"") + id + "." + key + "\"");
  res.set_header("ETag", "\"" + id + "-" + tag + "\"");
  res.set_header("Cache-Control", "private, max-age=3600");
  res.set_header("Accept-Ranges", "bytes");
  const RangeDecision d = decide_range(range, size);
  if (d.kind == RangeDecision::Kind::kUnsatisfiable) {
    res.set_header("Content-Range", "bytes */" + std::to_string(size));
    Problem p = make_problem(416, "range-not-satisfiable", "Range Not Satisfiable",
                             "the range lies outside the " + std::to_string(size) +
                                 "-byte result");
    p.extensions["size"] = size;
    send_problem(res, p, job_path(id) + "/result");
    return true;
  }
  std::uint64_t first = 0;
  std::uint64_t length = size;
  if (d.kind == RangeDecision::Kind::kPartial) {
    first = d.first;
    length = d.last - d.first + 1;
    res.status = 206;
    res.set_header("Content-Range", "bytes " + std::to_string(d.first) + "-" +
                                        std::to_string(d.last) + "/" + std::to_string(size));
  }
  res.set_content_provider(
      std::size_t(length), mime_type(format),
      [stream = stored->stream, first](size_t offset, size_t length, httplib::DataSink& sink) {
        char buf[1 << 16];
        stream->clear();
        stream->seekg(std::streamoff(first + offset));
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
