#pragma once
// The web dashboard's static files (server/dashboard/: index.html, dashboard.js, dashboard.css),
// compiled into the binary by cmake/embed_documents.cmake. nullptr for an unknown name.
#include <string>

namespace penumbra::server {
const std::string* dashboard_file(const std::string& name);
}  // namespace penumbra::server
