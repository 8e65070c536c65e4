#include "app/load_report.h"

#include <cstdio>

namespace penumbra::app {

bool report_load_problems(const std::string& file, const api::LoadResult& result) {
  for (const api::Diagnostic& warning : result.warnings)
    std::fprintf(stderr, "%s: warning: %s\n", file.c_str(), warning.to_string().c_str());
  for (const api::Diagnostic& error : result.errors)
    std::fprintf(stderr, "%s: %s\n", file.c_str(), error.to_string().c_str());
  return result.ok();
}

}  // namespace penumbra::app
