#include "server/http/json_response.h"

#include <httplib.h>

namespace penumbra::server {

void send_json(httplib::Response& res, int status, const nlohmann::ordered_json& body) {
  using json = nlohmann::ordered_json;
  res.status = status;
  // Invalid UTF-8 (from a scene's strings) is replaced, never thrown from here.
  res.set_content(body.dump(2, ' ', false, json::error_handler_t::replace) + "\n",
                  "application/json");
}

nlohmann::ordered_json diagnostics_json(const std::vector<api::Diagnostic>& ds) {
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (const auto& d : ds) a.push_back({{"pointer", d.pointer}, {"detail", d.message}});
  return a;
}

}  // namespace penumbra::server
