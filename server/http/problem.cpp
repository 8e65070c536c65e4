#include "server/http/problem.h"

#include <httplib.h>

#include <cmath>

namespace penumbra::server {

const char* status_reason(int status) {
  switch (status) {
    case 400:
      return "Bad Request";
    case 401:
      return "Unauthorized";
    case 403:
      return "Forbidden";
    case 404:
      return "Not Found";
    case 405:
      return "Method Not Allowed";
    case 406:
      return "Not Acceptable";
    case 409:
      return "Conflict";
    case 411:
      return "Length Required";
    case 413:
      return "Content Too Large";
    case 414:
      return "URI Too Long";
    case 415:
      return "Unsupported Media Type";
    case 416:
      return "Range Not Satisfiable";
    case 422:
      return "Unprocessable Content";
    case 429:
      return "Too Many Requests";
    case 500:
      return "Internal Server Error";
    case 503:
      return "Service Unavailable";
    default:
      return "Error";
  }
}

Problem make_problem(int status, const std::string& slug, const std::string& title,
                     const std::string& detail) {
  Problem p;
  p.status = status;
  p.type = "urn:penumbra:problem:" + slug;
  p.title = title;
  p.detail = detail;
  return p;
}

Problem status_problem(int status, const std::string& detail) {
  Problem p;
  p.status = status;
  p.type = "about:blank";
  p.title = status_reason(status);  // RFC 9457 4.2.1: about:blank's title is the reason phrase
  p.detail = detail;
  return p;
}

Problem invalid_parameter(const std::string& parameter, const std::string& what) {
  Problem p =
      make_problem(400, "invalid-parameter", "Invalid query parameter", parameter + " " + what);
  p.extensions["errors"] =
      nlohmann::ordered_json::array({{{"parameter", parameter}, {"detail", what}}});
  return p;
}

nlohmann::ordered_json problem_json(const Problem& p, const std::string& instance) {
  nlohmann::ordered_json j = {{"type", p.type}, {"title", p.title}, {"status", p.status}};
  if (!p.detail.empty()) j["detail"] = p.detail;
  if (!instance.empty()) j["instance"] = instance;
  for (const auto& [key, value] : p.extensions.items()) j[key] = value;
  return j;
}

void send_problem(httplib::Response& res, const Problem& p, const std::string& instance) {
  res.status = p.status;
  if (p.retry_after_seconds > 0)
    res.set_header("Retry-After", std::to_string(long(std::ceil(p.retry_after_seconds))));
  // The request path is user input: dump() escapes it, and invalid UTF-8 is replaced, not thrown.
  res.set_content(problem_json(p, instance)
                      .dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace),
                  "application/problem+json");
}

void send_problem(httplib::Response& res, const httplib::Request& req, const Problem& p) {
  send_problem(res, p, req.path);
}

}  // namespace penumbra::server
