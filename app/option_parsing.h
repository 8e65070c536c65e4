#pragma once
// Small command-line parsing helpers shared by the subcommands.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "api/scene_loader.h"

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
  // A switch's value: "--x=V" or a following "true"/"false" (consumed), else "true".
  bool switch_value(std::string* out);
  bool int_value(long long lo, long long hi, long long* out);
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

// If the current option overrides the scene's "render" block (api/render_overrides.h), appends
// it as typed and returns true (check p.failed() for a missing value). Its value is checked by
// api/ with the scene, by the same code and limits as the JSON field.
bool parse_render_override(OptionParser& p, std::vector<api::RenderOverride>& overrides);

// The arguments of a command that takes only files and --help (validate, info): the files in
// order ("--" ends the options). nullopt when the command is done, with *exit_code set: 0 after
// --help, 2 after printing a usage error (an unknown option, no file).
std::optional<std::vector<std::string>> file_arguments(int argc, char** argv, const char* command,
                                                       void (*print_help)(std::FILE*),
                                                       int* exit_code);

}  // namespace penumbra::app
