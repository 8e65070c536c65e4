#pragma once
// Typed, strict access to the members of one JSON object, reporting every problem through
// Diagnostics with the JSON pointer of the member. The parsers in api/ are written in terms of
// it, so that "wrong type", "missing", "out of range" and "unknown key" read the same everywhere.
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "api/diagnostics.h"

namespace penumbra::api {

using Json = nlohmann::json;

// Largest magnitude accepted for any real-valued field. The renderer works in single precision
// (max ~3.4e38); 1e30 leaves room for products such as |u x v| of a quad without reaching
// infinity, while still being far beyond any sensible scene unit.
inline constexpr double kMaxMagnitude = 1e30;

// An interval of allowed values, able to describe itself in an error message.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  static Range any() { return {}; }
  static Range at_least(double x) { return {x, Range{}.hi, false, false}; }
  static Range greater_than(double x) { return {x, Range{}.hi, true, false}; }
  static Range closed(double a, double b) { return {a, b, false, false}; }
  static Range open(double a, double b) { return {a, b, true, true}; }

  bool contains(double x) const;
  std::string describe() const;  // e.g. "must be in [0, 1]", "must be > 0"
};

// Shortest round-trip text of a number ("0.5", "8192", "1e+30").
std::string format_number(double x);

// Value checks on a single JSON value; each reports at `pointer` and returns nullopt on failure.
std::optional<double> read_number(const Json& value, const std::string& pointer, Diagnostics& diag,
                                  const Range& range = Range::any());
// Integral numbers only (2 and 2.0 pass, 2.5 does not).
std::optional<int64_t> read_integer(const Json& value, const std::string& pointer,
                                     Diagnostics& diag, const Range& range = Range::any());
std::optional<uint64_t> read_unsigned(const Json& value, const std::string& pointer,
                                      Diagnostics& diag);
std::optional<std::string> read_string(const Json& value, const std::string& pointer,
                                       Diagnostics& diag);
// An array of exactly 3 numbers; `range` applies to each component (reported on /i).
std::optional<glm::dvec3> read_vec3(const Json& value, const std::string& pointer,
                                    Diagnostics& diag, const Range& range = Range::any());

// A collection's size against its limit, checked before any element is read: over it, reports
// "<count> <what> exceed the limit of <limit> (<limit_name>)" on `pointer` and returns false.
bool within_count_limit(std::size_t count, int64_t limit, std::string_view what,
                        std::string_view limit_name, const std::string& pointer, Diagnostics& diag);

enum class Presence { kOptional, kRequired };

class ObjectReader {
 public:
  // Reports "must be an object" when `value` is not one; every accessor then returns nullopt.
  ObjectReader(const Json& value, std::string pointer, Diagnostics& diag);

  bool valid() const { return object_ != nullptr; }
  const std::string& pointer() const { return pointer_; }
  std::string pointer_of(std::string_view key) const { return child_pointer(pointer_, key); }
  Diagnostics& diagnostics() const { return diag_; }
  bool has(std::string_view key) const;

  // Declares keys as known without reading them (e.g. fields read through get()).
  void allow(std::initializer_list<std::string_view> keys);

  // The member, or nullptr (with an error when required and missing). Marks the key known.
  const Json* get(std::string_view key, Presence presence = Presence::kOptional);

  std::optional<double> number(std::string_view key, const Range& range = Range::any(),
                               Presence presence = Presence::kOptional);
  std::optional<int64_t> integer(std::string_view key, const Range& range = Range::any(),
                                 Presence presence = Presence::kOptional);
  std::optional<uint64_t> unsigned_integer(std::string_view key,
                                           Presence presence = Presence::kOptional);
  std::optional<std::string> string(std::string_view key, Presence presence = Presence::kOptional);
  std::optional<glm::dvec3> vec3(std::string_view key, const Range& range = Range::any(),
                                 Presence presence = Presence::kOptional);
  // The member if it is an array (error otherwise).
  const Json* array(std::string_view key, Presence presence = Presence::kOptional);

  void error(std::string_view key, std::string message) const;
  void warning(std::string_view key, std::string message) const;

  // Reports every member that no accessor or allow() named, as an error, suggesting the closest
  // known key. Unknown keys are errors, not warnings: a misspelt optional field ("roughnes")
  // would otherwise silently fall back to its default.
  void report_unknown_keys() const;

 private:
  const Json* object_ = nullptr;
  std::string pointer_;
  Diagnostics& diag_;
  std::set<std::string, std::less<>> known_;
};

}  // namespace penumbra::api
