#pragma once
// How the commands print a scene load's problems: '<file>: warning: <pointer>: <message>' for
// each warning, then '<file>: <pointer>: <message>' for each error, all on stderr.
#include <string>

#include "api/scene_loader.h"

namespace penumbra::app {

// Returns result.ok().
bool report_load_problems(const std::string& file, const api::LoadResult& result);

}  // namespace penumbra::app
