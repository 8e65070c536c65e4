#include "app/option_parsing.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "api/render_overrides.h"

namespace penumbra::app {

bool OptionParser::next() {
  if (++index_ >= argc_) return false;
  current_ = argv_[index_];
  inline_value_.reset();
  if (current_.rfind("--", 0) == 0) {
    const size_t eq = current_.find('=');
    if (eq != std::string::npos) {
      inline_value_ = current_.substr(eq + 1);
      current_ = current_.substr(0, eq);
    }
  }
  return true;
}

bool OptionParser::value(std::string* out) {
  if (inline_value_) {
    *out = *inline_value_;
    return true;
  }
  if (index_ + 1 >= argc_) {
    failed_ = true;
    error_ = current_ + " needs a value";
    return false;
  }
  *out = argv_[++index_];
  return true;
}

bool OptionParser::int_value(long long lo, long long hi, long long* out) {
  std::string v;
  if (!value(&v)) return false;
  errno = 0;
  char* end = nullptr;
  const long long x = std::strtoll(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || errno == ERANGE || x < lo || x > hi) {
    failed_ = true;
    error_ = current_ + " takes a whole number from " + std::to_string(lo) + " to " + std::to_string(hi);
    return false;
  }
  *out = x;
  return true;
}

int OptionParser::fail(const char* usage, const std::string& error) {
  const std::string& e = error.empty() ? error_ : error;
  if (!e.empty()) std::fprintf(stderr, "error: %s\n\n", e.c_str());
  std::fputs(usage, stderr);
  return 2;
}

bool OptionParser::switch_value(std::string* out) {
  if (inline_value_) {
    *out = *inline_value_;
    return true;
  }
  if (index_ + 1 < argc_ && (!std::strcmp(argv_[index_ + 1], "true") ||
                             !std::strcmp(argv_[index_ + 1], "false"))) {
    *out = argv_[++index_];
    return true;
  }
  *out = "true";
  return true;
}

bool parse_render_override(OptionParser& p, std::vector<api::RenderOverride>& overrides) {
  if (!api::is_render_override_flag(p.arg())) return false;
  if (api::is_switch_override_flag(p.arg())) {
    std::string value;
    p.switch_value(&value);
    overrides.push_back({p.arg(), std::move(value)});
    return true;
  }
  std::string value;
  if (p.value(&value)) overrides.push_back({p.arg(), std::move(value)});
  return true;
}

std::optional<std::vector<std::string>> file_arguments(int argc, char** argv, const char* command,
                                                       void (*print_help)(std::FILE*),
                                                       int* exit_code) {
  std::vector<std::string> files;
  bool options_done = false;
  for (int i = 1; i < argc; ++i) {
    const char* arg = argv[i];
    if (!options_done && (!std::strcmp(arg, "--help") || !std::strcmp(arg, "-h"))) {
      print_help(stdout);
      *exit_code = 0;
      return std::nullopt;
    }
    if (!options_done && !std::strcmp(arg, "--")) {
      options_done = true;
      continue;
    }
    if (!options_done && arg[0] == '-' && arg[1] != '\0') {
      std::fprintf(stderr, "penumbra %s: unknown option '%s'\n", command, arg);
      print_help(stderr);
      *exit_code = 2;
      return std::nullopt;
    }
    files.emplace_back(arg);
  }
  if (files.empty()) {
    print_help(stderr);
    *exit_code = 2;
    return std::nullopt;
  }
  return files;
}

}  // namespace penumbra::app
