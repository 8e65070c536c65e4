#pragma once
// Small command-line parsing helpers shared by the subcommands.
#include <optional>
#include <string>

#include "renderer/scene/scene_input.h"

namespace penumbra::app {

// Walks argv: options ("--name value" or "--name=value") and positional arguments.
class OptionParser {
 public:
  OptionParser(int argc, char** argv) : argc_(argc), argv_(argv) {}
  bool next();                       // advances to the next argument
  const char* arg() const { return current_.c_str(); }
  bool is(const char* name) const { return current_ == name; }
  bool positional() const { return current_.empty() || current_[0] != '-' || current_ == "-"; }
  bool value(std::string* out);      // the option's value, false if missing
  bool int_value(long long lo, long long hi, long long* out);
  bool double_value(double lo, double hi, double* out);
  bool failed() const { return failed_; }
  // Prints the error (if any) and usage to stderr, returns exit code 2.
  int fail(const char* usage, const std::string& error = "");

 private:
  int argc_;
  char** argv_;
  int index_ = 0;
  std::string current_;
  std::optional<std::string> inline_value_;
  bool failed_ = false;
  std::string error_;
};

// Flags that override a scene's "render" block: --spp --width --height --seed --threads
// --max-depth --integrator --time-limit --noise-threshold.
struct OptionalOverrides {
  std::optional<long long> spp, width, height, seed, threads, max_depth;
  std::optional<std::string> integrator;
  std::optional<double> time_limit, noise_threshold;

  // True if the current option is one of these (check p.failed() for a bad value).
  bool parse(OptionParser& p);
  // Applies them; returns an error message or "".
  std::string apply(RenderSettings* settings) const;
};

}  // namespace penumbra::app
