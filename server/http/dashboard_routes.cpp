// GET / and /dashboard/{file}: the web dashboard's static page (server/dashboard/), compiled
// in. The page holds no data: every job it shows it fetches from the API with the user's token,
// so these routes need none (server/http/route_table.h, is_public_route).
#include <httplib.h>

#include "server/http/dashboard_files.h"
#include "server/http/problem.h"
#include "server/http/route_context.h"
#include "server/http/route_table.h"

namespace penumbra::server {
namespace {

const char* content_type(const std::string& name) {
  auto ends = [&](const char* ext) {
    const std::string e(ext);
    return name.size() >= e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".svg")) return "image/svg+xml";
  if (ends(".png")) return "image/png";
  return "application/octet-stream";
}

void send_file(const httplib::Request& req, httplib::Response& res, const std::string& name) {
  const std::string* file = dashboard_file(name);
  if (!file) return send_problem(res, req, status_problem(404, "no such dashboard file"));
  // Only the page's own scripts and styles, images from the API as blobs, requests to this
  // origin; no framing (clickjacking), no sniffing, no referrer leaving the page.
  res.set_header("Content-Security-Policy",
                 "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' blob:; "
                 "connect-src 'self'; form-action 'none'; base-uri 'none'; frame-ancestors 'none'");
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_header("Referrer-Policy", "no-referrer");
  res.set_header("Cache-Control", "no-cache");
  res.set_content(*file, content_type(name));
}

}  // namespace

void add_dashboard_routes(httplib::Server& s, const RouteContext&) {
  s.Get("/", [](const httplib::Request& req, httplib::Response& res) {
    send_file(req, res, "index.html");
  });
  s.Get(kDashboardRoute,
        [](const httplib::Request& req, httplib::Response& res) {
          send_file(req, res, req.matches[1].str());
        });
}

}  // namespace penumbra::server
