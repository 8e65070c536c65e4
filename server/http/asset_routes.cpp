// The content-addressed asset store over HTTP (issue 12; server/storage/asset_store.h):
//   PUT  /v1/assets/{sha256}   upload a file under its SHA-256 (verified while it streams in)
//   GET  /v1/assets/{sha256}   download it; HEAD says whether it is stored (and its size)
//   POST /v1/assets/missing    {"hashes": ["sha256:..."]} -> {"missing": [...]}: what to upload
#include <httplib.h>

#include <algorithm>

#include "api/diagnostics.h"
#include "api/job_submission.h"
#include "api/json_document.h"
#include "server/http/json_response.h"
#include "server/http/problem.h"
#include "server/http/route_context.h"
#include "server/http/route_table.h"

namespace penumbra::server {
namespace {

using json = nlohmann::ordered_json;

std::string asset_location(const std::string& hash) { return "/v1/assets/" + hash; }

json asset_json(const std::string& hash, std::uint64_t size) {
  return {{"hash", "sha256:" + hash}, {"size", size}};
}

Problem bad_hash(const std::string& text) {
  Problem p = make_problem(400, "invalid-asset-hash", "Invalid asset hash",
                           api::quote_user_string(text) +
                               " is not a SHA-256: the path ends in 64 lowercase hex digits");
  return p;
}

Problem no_assets() {
  return status_problem(404, "this server keeps no assets");
}

void put_asset(const RouteContext& c, const httplib::Request& req, httplib::Response& res,
               const httplib::ContentReader& read_body) {
  AssetStore* store = c.jobs.assets();
  if (!store) return send_problem(res, req, no_assets());
  const std::string hash = req.matches[1];
  if (hash == "missing") {
    res.set_header("Allow", "POST");
    return send_problem(res, req, status_problem(405, "PUT is not allowed here; allowed: POST"));
  }
  if (!api::is_sha256_hex(hash)) return send_problem(res, req, bad_hash(hash));
  // Known already: answered without reading the body (the connection is then closed, as its
  // unread body follows; with Expect: 100-continue the body is never sent, http_server.cpp).
  if (const auto size = store->size_of(hash)) {
    res.set_header("Location", asset_location(hash));
    return send_json(res, 200, asset_json(hash, *size));
  }
  std::unique_ptr<AssetUpload> upload = store->begin_upload(hash);
  const bool complete =
      read_body([&](const char* data, size_t n) { return upload->write(data, n); });
  if (upload->too_large()) {
    Problem p = make_problem(413, "asset-too-large", "Content Too Large",
                             "an asset may have at most " +
                                 std::to_string(store->limits().max_asset_bytes) +
                                 " bytes (--max-asset-size)");
    p.extensions["limit"] = store->limits().max_asset_bytes;
    return send_problem(res, req, p);
  }
  if (!complete) {
    return send_problem(res, req, status_problem(400, "the body ended before its Content-Length"));
  }
  const PutResult r = store->finish_upload(std::move(upload));
  switch (r.status) {
    case PutStatus::kStored:
      res.set_header("Location", asset_location(hash));
      return send_json(res, 201, asset_json(hash, r.size));
    case PutStatus::kAlreadyStored:
      res.set_header("Location", asset_location(hash));
      return send_json(res, 200, asset_json(hash, r.size));
    case PutStatus::kMismatch: {
      Problem p = make_problem(422, "asset-hash-mismatch", "Asset hash mismatch",
                               "the body's SHA-256 is " + r.actual_hash + ", not " + hash +
                                   "; nothing was stored");
      p.extensions["expected"] = "sha256:" + hash;
      p.extensions["actual"] = "sha256:" + r.actual_hash;
      return send_problem(res, req, p);
    }
    case PutStatus::kTooLarge:
      return send_problem(res, req, status_problem(413, "the asset is too large"));
    case PutStatus::kNoRoom: {
      Problem p = make_problem(
          507, "asset-store-full", "Insufficient Storage",
          "the asset store (--max-asset-store " +
              std::to_string(store->limits().max_store_bytes) + " bytes) is full of assets that queued or running jobs use; retry later");
      p.extensions["limit"] = store->limits().max_store_bytes;
      p.retry_after_seconds = 30;
      return send_problem(res, req, p);
    }
  }
}

void get_asset(const RouteContext& c, const httplib::Request& req, httplib::Response& res) {
  AssetStore* store = c.jobs.assets();
  if (!store) return send_problem(res, req, no_assets());
  const std::string hash = req.matches[1];
  if (hash == "missing") {
    res.set_header("Allow", "POST");
    return send_problem(res, req, status_problem(405, req.method + " is not allowed here; allowed: POST"));
  }
  if (!api::is_sha256_hex(hash)) return send_problem(res, req, bad_hash(hash));
  auto opened = store->open(hash);
  if (!opened) return send_problem(res, req, status_problem(404, "no asset sha256:" + hash));
  auto [stream, size] = *opened;
  // Content never changes under its hash.
  res.set_header("ETag", "\"sha256:" + hash + "\"");
  res.set_header("Cache-Control", "private, max-age=31536000, immutable");
  res.set_content_provider(
      std::size_t(size), "application/octet-stream",
      [stream = stream](size_t offset, size_t length, httplib::DataSink& sink) {
        char buf[1 << 16];
        stream->clear();
        stream->seekg(std::streamoff(offset));
        stream->read(buf, std::streamsize(std::min(length, sizeof buf)));
        const auto got = stream->gcount();
        if (got <= 0) return false;
        sink.write(buf, size_t(got));
        return true;
      });
}

void post_missing(const RouteContext& c, const httplib::Request& req, httplib::Response& res) {
  AssetStore* store = c.jobs.assets();
  if (!store) return send_problem(res, req, no_assets());
  api::Diagnostics diag;
  const api::JsonDocument doc = api::parse_json_document(req.body, 8, diag);
  if (doc.syntax_error) {
    Problem p = make_problem(400, "malformed-json", "Malformed JSON", "the body is not JSON");
    p.extensions["errors"] = diagnostics_json(diag.take_errors());
    return send_problem(res, req, p);
  }
  const api::Json& root = *doc.value;
  std::vector<std::string> hashes;
  if (!root.is_object() || !root.contains("hashes") || !root["hashes"].is_array()) {
    diag.error(root.is_object() && root.contains("hashes") ? "/hashes" : "",
               "the body is {\"hashes\": [\"sha256:<64 hex digits>\", ...]}");
  } else {
    for (const auto& [key, _] : root.items())
      if (key != "hashes") diag.error(api::child_pointer("", key), "unknown member");
    const api::Json& list = root["hashes"];
    for (std::size_t i = 0; i < list.size(); ++i) {
      const auto hash = list[i].is_string() ? api::parse_hash_reference(list[i].get<std::string>())
                                            : std::nullopt;
      if (!hash) {
        diag.error(api::child_pointer("/hashes", i),
                   "must be \"sha256:\" followed by 64 lowercase hex digits");
        continue;
      }
      hashes.push_back(*hash);
    }
  }
  if (diag.has_errors()) {
    const auto errors = diag.take_errors();
    Problem p = make_problem(422, "invalid-request", "Invalid request",
                             std::to_string(errors.size()) + " error(s) in the body; see errors");
    p.extensions["errors"] = diagnostics_json(errors);
    return send_problem(res, req, p);
  }
  json out = {{"missing", json::array()}};
  for (const std::string& h : store->missing(hashes)) out["missing"].push_back("sha256:" + h);
  send_json(res, 200, out);
}

}  // namespace

void add_asset_routes(httplib::Server& s, const RouteContext& c) {
  s.Post("/v1/assets/missing", [&c](const httplib::Request& req, httplib::Response& res) {
    post_missing(c, req, res);
  });
  s.Put(kAssetRoute, [&c](const httplib::Request& req, httplib::Response& res,
                          const httplib::ContentReader& reader) { put_asset(c, req, res, reader); });
  s.Get(kAssetRoute,
        [&c](const httplib::Request& req, httplib::Response& res) { get_asset(c, req, res); });
}

}  // namespace penumbra::server
