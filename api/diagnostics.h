#pragma once
// Collects the errors and warnings of one scene load. Both lists are capped so a hostile scene
// (a million bad indices) cannot make the report itself unbounded.
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "api/scene_loader.h"

namespace penumbra::api {

class Diagnostics {
 public:
  static constexpr std::size_t kMaxReported = 100;

  void error(std::string pointer, std::string message);
  void error(Diagnostic diagnostic);
  void warning(std::string pointer, std::string message);

  // From now on, diagnostics on `pointer` are about a value the command-line flag `flag`
  // supplied, and carry it (Diagnostic::flag). Earlier ones, such as a duplicate key in the JSON
  // text, stay about the JSON.
  void attribute_to_flag(std::string pointer, std::string flag);

  std::size_t error_count() const { return error_count_; }
  bool has_errors() const { return error_count_ > 0; }

  // Moves the diagnostics out, appending a note about how many were left out.
  std::vector<Diagnostic> take_errors();
  std::vector<Diagnostic> take_warnings();

 private:
  std::vector<Diagnostic> errors_;
  std::vector<Diagnostic> warnings_;
  std::vector<std::pair<std::string, std::string>> flags_;  // pointer -> flag
  std::size_t error_count_ = 0;
  std::size_t warning_count_ = 0;
};

// RFC 6901: "~" becomes "~0" and "/" becomes "~1" inside one reference token.
std::string escape_pointer_token(std::string_view token);
// `base` + "/" + escaped token.
std::string child_pointer(const std::string& base, std::string_view token);
std::string child_pointer(const std::string& base, std::size_t index);

// A user-supplied string made safe to quote in a message: control characters replaced and
// truncated at a UTF-8 character boundary (messages end up in JSON bodies, which must stay
// valid UTF-8).
std::string quote_user_string(std::string_view text);

// The candidate closest to `word` by edit distance, or "" when none is close enough to be a
// plausible typo.
std::string closest_match(std::string_view word, const std::vector<std::string>& candidates);
// " (did you mean 'x'?)" or "".
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace penumbra::api
