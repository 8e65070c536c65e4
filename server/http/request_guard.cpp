#include "server/http/request_guard.h"

#include <httplib.h>

#include <algorithm>
#include <cctype>
#include <string>

#include "server/http/one_shot_job.h"
#include "server/http/route_table.h"
#include "server/text_util.h"

namespace penumbra::server {
namespace {

bool is_digits(const std::string& s) {
  if (s.empty() || s.size() > 19) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  return true;
}

}  // namespace

std::optional<Problem> guard_request(const httplib::Request& req, const GuardSettings& settings,
                                     const BearerAuth& auth) {
  // The library's parsed ranges are dropped: it would cut any answer, problem documents
  // included, and it does not check a range against the size of the body (issue 15: 206 with
  // Content-Length 18446744073609554395). Result routes read the header themselves
  // (byte_range.h); elsewhere Range is ignored, as RFC 9110 section 14.2 allows.
  // (The Request object is not const in the library; only the handler's view of it is.)
  const_cast<httplib::Request&>(req).ranges.clear();
  // Liveness must answer whatever the token: orchestrators probe it without credentials. The
  // dashboard's static files hold no data (they fetch it with the user's token).
  if (auth.enabled() && !is_public_route(req.path) &&
      !auth.allows(req.get_header_value("Authorization"))) {
    Problem p = make_problem(401, "unauthorized", "Unauthorized",
                             "send 'Authorization: Bearer <token>' (the server's --token)");
    return p;
  }
  if (req.has_header("Transfer-Encoding")) {
    // A chunked body has no length to check against the limit before it is read.
    return make_problem(411, "length-required", "Length Required",
                        "Transfer-Encoding is not accepted; send the body with Content-Length");
  }
  if (req.get_header_value_count("Content-Length") > 1)
    return make_problem(400, "bad-framing", "Bad Request", "more than one Content-Length header");
  if (req.has_header("Content-Encoding")) {
    const std::string enc =
        ascii_lower(std::string(trim_ows(req.get_header_value("Content-Encoding"))));
    if (enc != "identity")
      return make_problem(
          415, "unsupported-content-encoding", "Unsupported Media Type",
          "Content-Encoding '" + enc + "' is not accepted; send the body uncompressed");
  }
  const bool has_length = req.has_header("Content-Length");
  const std::string length_text(trim_ows(req.get_header_value("Content-Length")));
  if (has_length && !is_digits(length_text))
    return make_problem(400, "bad-framing", "Bad Request", "Content-Length is not a number");
  if (req.method == "POST" || req.method == "PUT" || req.method == "PATCH") {
    if (!has_length)
      return make_problem(411, "length-required", "Length Required",
                          "a request body needs a Content-Length header");
  }
  // The one-shot job forms (server/http/one_shot_job.h) carry files: a multipart form or a glTF
  // binary, up to --max-asset-size. Their Content-Type moves to an internal header so that the
  // library does not parse the multipart body itself (it would, without bounds, before any
  // handler); a client-sent copy of that header is dropped. The guard may run twice (also for
  // Expect: 100-continue), so an already rewritten request is recognised by its marker type.
  auto& headers = const_cast<httplib::Request&>(req).headers;
  const std::string media = ascii_lower(
      std::string(trim_ows(req.get_header_value("Content-Type").substr(
          0, req.get_header_value("Content-Type").find(';')))));
  bool one_shot = req.has_header(kOneShotTypeHeader) && media == kOneShotMarkerType;
  if (!one_shot) headers.erase(kOneShotTypeHeader);
  if (!one_shot && req.method == "POST" && req.path == "/v1/jobs" &&
      (media == "multipart/form-data" || media == "model/gltf-binary")) {
    const std::string original = req.get_header_value("Content-Type");
    headers.erase("Content-Type");
    headers.emplace("Content-Type", kOneShotMarkerType);
    headers.emplace(kOneShotTypeHeader, original);
    one_shot = true;
  }
  if (has_length) {
    const unsigned long long length = std::stoull(length_text);
    // An asset upload streams to disk (never held in memory) under its own limit; a one-shot
    // form counts as one upload.
    const bool asset_upload =
        one_shot || (req.method == "PUT" && req.path.rfind("/v1/assets/", 0) == 0);
    const std::size_t limit = asset_upload ? std::max(settings.max_asset_bytes, settings.max_body_bytes)
                                           : settings.max_body_bytes;
    const char* flag = asset_upload ? "--max-asset-size" : "--max-body";
    if (length > limit) {
      Problem p = make_problem(413, asset_upload ? "asset-too-large" : "body-too-large",
                               "Content Too Large",
                               "the body has " + length_text + " bytes; the limit is " +
                                   std::to_string(limit) + " (" + flag + ")");
      p.extensions["limit"] = limit;
      return p;
    }
  }
  if (req.has_header("Range") && req.get_header_value("Range").find(',') != std::string::npos) {
    // One range at most: a many-range request multiplies the response size.
    return make_problem(416, "multiple-ranges", "Range Not Satisfiable",
                        "only a single byte range is served");
  }
  if (req.method == "POST" && req.has_header("Content-Type") && !one_shot) {
    // Checked before the body is read: the library would otherwise parse multipart bodies.
    std::string type = ascii_lower(req.get_header_value("Content-Type"));
    type = std::string(trim_ows(type.substr(0, type.find(';'))));
    const bool json_like =
        type == "application/json" || (type.rfind("application/", 0) == 0 && type.size() > 5 &&
                                       type.compare(type.size() - 5, 5, "+json") == 0);
    // curl --data-binary sends application/x-www-form-urlencoded unless told otherwise; it is
    // read as JSON too so a curl line without -H works. The library would parse such a body as a
    // form and refuse it above 8192 bytes (CPPHTTPLIB_FORM_URL_ENCODED_PAYLOAD_MAX_LENGTH) before
    // any handler runs, so the header is rewritten here, before the body is read.
    if (type == "application/x-www-form-urlencoded") {
      auto& headers = const_cast<httplib::Request&>(req).headers;
      headers.erase("Content-Type");
      headers.emplace("Content-Type", "application/json");
    } else if (!json_like) {
      Problem p = make_problem(415, "unsupported-media-type", "Unsupported Media Type",
                               "the body must be a JSON scene: send the header "
                               "'Content-Type: application/json' (got '" + type + "'); POST "
                               "/v1/jobs also takes multipart/form-data and model/gltf-binary");
      p.extensions["header"] = "Content-Type";
      return p;
    }
  }
  return std::nullopt;
}

}  // namespace penumbra::server
