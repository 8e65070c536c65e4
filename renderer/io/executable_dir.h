#pragma once
// The folder of the running executable (from /proc/self/exe): where optional shared libraries
// loaded at run time are looked for (<dir>/../lib/penumbra/...). "" if it cannot be read.
#include <string>

namespace penumbra {
std::string executable_dir();
}  // namespace penumbra
