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
    case 408:
      return "Request Timeout";
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
    case 431:
      return "Request Header Fields Too Large";
    case 507:
      return "Insufficient Storage";
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

const char* status_slug(int status) {
  switch (status) {
    case 400:
      return "bad-request";
    case 404:
      return "not-found";
    case 405:
      return "method-not-allowed";
    case 408:
      return "request-timeout";
    case 413:
      return "body-too-large";
    case 414:
      return "uri-too-long";
    case 416:
      return "range-not-satisfiable";
    case 431:
      return "headers-too-large";
    case 500:
      return "internal-error";
    case 503:
      return "unavailable";
    default:
      return status >= 500 ? "server-error" : "client-error";
  }
}

Problem status_problem(int status, const std::string& detail) {
  // A type of our own even for plain statuses: clients switch on `type` alone (issue 15).
  return make_problem(status, status_slug(status), status_reason(status), detail);
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
