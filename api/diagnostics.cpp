#include "api/diagnostics.h"

#include <algorithm>

namespace penumbra::api {

namespace {
void attribute(Diagnostic& d, const std::vector<std::pair<std::string, std::string>>& flags) {
  for (const auto& [pointer, flag] : flags)
    // The flag's field or anything inside it (--aov sets /render/outputs; its items err at
    // /render/outputs/1).
    if (d.flag.empty() && (d.pointer == pointer || (d.pointer.size() > pointer.size() &&
                                                    d.pointer.compare(0, pointer.size(), pointer) == 0 &&
                                                    d.pointer[pointer.size()] == '/')))
      d.flag = flag;
}
}  // namespace

std::string Diagnostic::to_string() const {
  const std::string where = pointer.empty() ? "/" : pointer;
  if (flag.empty()) return where + ": " + message;
  return flag + (pointer.empty() ? "" : " (" + pointer + ")") + ": " + message;
}

void Diagnostics::error(std::string pointer, std::string message) {
  error(Diagnostic{std::move(pointer), std::move(message)});
}

void Diagnostics::error(Diagnostic diagnostic) {
  ++error_count_;
  if (errors_.size() >= kMaxReported) return;
  attribute(diagnostic, flags_);
  errors_.push_back(std::move(diagnostic));
}

void Diagnostics::warning(std::string pointer, std::string message) {
  ++warning_count_;
  if (warnings_.size() >= kMaxReported) return;
  Diagnostic diagnostic{std::move(pointer), std::move(message)};
  attribute(diagnostic, flags_);
  warnings_.push_back(std::move(diagnostic));
}

void Diagnostics::attribute_to_flag(std::string pointer, std::string flag) {
  flags_.emplace_back(std::move(pointer), std::move(flag));
}

std::vector<Diagnostic> Diagnostics::take_errors() {
  if (error_count_ > errors_.size())
    errors_.push_back({"", std::to_string(error_count_ - errors_.size()) + " more errors not shown"});
  return std::move(errors_);
}

std::vector<Diagnostic> Diagnostics::take_warnings() {
  if (warning_count_ > warnings_.size())
    warnings_.push_back(
        {"", std::to_string(warning_count_ - warnings_.size()) + " more warnings not shown"});
  return std::move(warnings_);
}

std::string escape_pointer_token(std::string_view token) {
  std::string out;
  out.reserve(token.size());
  for (char c : token) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

std::string child_pointer(const std::string& base, std::string_view token) {
  return base + "/" + escape_pointer_token(token);
}

std::string child_pointer(const std::string& base, std::size_t index) {
  return base + "/" + std::to_string(index);
}

std::string quote_user_string(std::string_view text) {
  constexpr std::size_t kMaxBytes = 64;
  std::string out = "'";
  std::size_t i = 0;
  for (; i < text.size() && i < kMaxBytes; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    out += c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c);
  }
  if (i < text.size()) {
    // Drop a partial UTF-8 sequence: continuation bytes are 10xxxxxx, so back up to the byte
    // that starts the character that was cut.
    std::size_t end = out.size();
    std::size_t k = end;
    while (k > 1 && (static_cast<unsigned char>(out[k - 1]) & 0xC0) == 0x80) --k;
    if (k > 1 && static_cast<unsigned char>(out[k - 1]) >= 0xC0) out.resize(k - 1);
    out += "...";
  }
  out += "'";
  return out;
}

namespace {
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + cost});
      diagonal = above;
    }
  }
  return row[b.size()];
}
}  // namespace

std::string closest_match(std::string_view word, const std::vector<std::string>& candidates) {
  // Keys are short; anything longer than this is not a typo of one and would only cost time.
  if (word.size() > 64) return "";
  std::string best;
  std::size_t best_distance = SIZE_MAX;
  for (const std::string& candidate : candidates) {
    const std::size_t d = edit_distance(word, candidate);
    if (d < best_distance) {
      best_distance = d;
      best = candidate;
    }
  }
  // A third of the length (at least 1, at most 3) edits is what a typo plausibly changes.
  const std::size_t allowed = std::clamp<std::size_t>(std::max(word.size(), best.size()) / 3, 1, 3);
  // Replacing every character is no typo ("x" is not a misspelt "g").
  const bool plausible = best_distance < std::max(word.size(), best.size());
  if (best_distance <= allowed && plausible) return best;
  // A shortened name ("aperture" for "aperture_radius") is far in edits but obvious.
  if (word.size() >= 3)
    for (const std::string& candidate : candidates)
      if (candidate.size() > word.size() && candidate.compare(0, word.size(), word) == 0)
        return candidate;
  return "";
}

std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates) {
  const std::string match = closest_match(word, candidates);
  return match.empty() ? "" : " (did you mean '" + match + "'?)";
}

}  // namespace penumbra::api
