#pragma once
// RFC 9457 problem details: every error answer of the service is application/problem+json.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace penumbra::server {

struct Problem {
  int status = 500;
  std::string type;    // a stable URN naming the kind of problem, never about:blank
  std::string title;   // short, the same for every occurrence of the type
  std::string detail;  // this occurrence, meant for people
  nlohmann::ordered_json extensions =
      nlohmann::ordered_json::object();  // e.g. "errors": [{pointer, detail}]
  double retry_after_seconds = 0;        // > 0 adds a Retry-After header
};

// A problem of one of the service's own types, "urn:penumbra:problem:<slug>".
Problem make_problem(int status, const std::string& slug, const std::string& title,
                     const std::string& detail);
// For statuses with one meaning (404, 405, ...): type urn:penumbra:problem:<status_slug(status)>.
Problem status_problem(int status, const std::string& detail);
// "not-found", "method-not-allowed" ...: the slug of a plain status.
const char* status_slug(int status);
// 400 invalid-parameter naming the query parameter: detail "<parameter> <what>" and
// errors: [{parameter, detail: what}].
Problem invalid_parameter(const std::string& parameter, const std::string& what);

nlohmann::ordered_json problem_json(const Problem& p, const std::string& instance);
void send_problem(httplib::Response& res, const Problem& p, const std::string& instance);
// The same with the request's path as the instance.
void send_problem(httplib::Response& res, const httplib::Request& req, const Problem& p);

const char* status_reason(int status);

}  // namespace penumbra::server
