#include "api/json_reader.h"

#include <charconv>
#include <cmath>

namespace penumbra::api {

bool Range::contains(double x) const {
  const bool above = lo_open ? x > lo : x >= lo;
  const bool below = hi_open ? x < hi : x <= hi;
  return above && below;
}

std::string Range::describe() const {
  const bool has_lo = std::isfinite(lo);
  const bool has_hi = std::isfinite(hi);
  if (has_lo && has_hi)
    return "must be in " + std::string(lo_open ? "(" : "[") + format_number(lo) + ", " +
           format_number(hi) + (hi_open ? ")" : "]");
  if (has_lo) return std::string("must be ") + (lo_open ? "> " : ">= ") + format_number(lo);
  if (has_hi) return std::string("must be ") + (hi_open ? "< " : "<= ") + format_number(hi);
  return "";
}

std::string format_number(double x) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, result.ptr);
}

namespace {
const char* type_name(const Json& value) {
  switch (value.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::boolean: return "a boolean";
    case Json::value_t::string: return "a string";
    case Json::value_t::array: return "an array";
    case Json::value_t::object: return "an object";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float: return "a number";
    default: return "an unsupported value";
  }
}

std::string expected(const char* what, const Json& value) {
  return std::string("must be ") + what + " (got " + type_name(value) + ")";
}
}  // namespace

std::optional<double> read_number(const Json& value, const std::string& pointer, Diagnostics& diag,
                                  const Range& range) {
  if (!value.is_number()) {
    diag.error(pointer, expected("a number", value));
    return std::nullopt;
  }
  const double x = value.get<double>();
  // JSON text cannot spell NaN or Inf, but this also guards documents built in code.
  if (!std::isfinite(x) || std::abs(x) > kMaxMagnitude) {
    diag.error(pointer, "must be a finite number of magnitude <= " + format_number(kMaxMagnitude));
    return std::nullopt;
  }
  if (!range.contains(x)) {
    diag.error(pointer, range.describe());
    return std::nullopt;
  }
  return x;
}

std::optional<int64_t> read_integer(const Json& value, const std::string& pointer,
                                     Diagnostics& diag, const Range& range) {
  std::optional<int64_t> result;
  if (value.is_number_unsigned()) {
    const uint64_t u = value.get<uint64_t>();
    if (u <= uint64_t(std::numeric_limits<int64_t>::max())) result = int64_t(u);
  } else if (value.is_number_integer()) {
    result = value.get<int64_t>();
  } else if (value.is_number_float()) {
    // 64.0 is an integer by JSON Schema's definition; 2.5 is not.
    const double x = value.get<double>();
    if (std::isfinite(x) && x == std::floor(x) && std::abs(x) < 9.2e18) result = int64_t(x);
  }
  if (!result) {
    diag.error(pointer, value.is_number() ? "must be an integer" : expected("an integer", value));
    return std::nullopt;
  }
  if (!range.contains(double(*result))) {
    diag.error(pointer, range.describe());
    return std::nullopt;
  }
  return result;
}

std::optional<uint64_t> read_unsigned(const Json& value, const std::string& pointer,
                                      Diagnostics& diag) {
  if (value.is_number_unsigned()) return value.get<uint64_t>();
  if (value.is_number_integer()) {
    // number_integer holds negatives, and nlohmann's "-0" (which is 0).
    if (value.get<int64_t>() == 0) return 0;
    diag.error(pointer, "must be >= 0");
    return std::nullopt;
  }
  if (value.is_number_float()) {
    const double x = value.get<double>();
    if (x != std::floor(x) || !std::isfinite(x)) {
      diag.error(pointer, "must be an integer");
      return std::nullopt;
    }
    if (x < 0 || x >= 18446744073709551616.0) {
      diag.error(pointer, "must be in [0, 18446744073709551615]");
      return std::nullopt;
    }
    return uint64_t(x);
  }
  diag.error(pointer, expected("a non-negative integer", value));
  return std::nullopt;
}

std::optional<std::string> read_string(const Json& value, const std::string& pointer,
                                       Diagnostics& diag) {
  if (!value.is_string()) {
    diag.error(pointer, expected("a string", value));
    return std::nullopt;
  }
  return value.get<std::string>();
}

std::optional<glm::dvec3> read_vec3(const Json& value, const std::string& pointer,
                                    Diagnostics& diag, const Range& range) {
  if (!value.is_array() || value.size() != 3) {
    diag.error(pointer, value.is_array()
                            ? "must be an array of 3 numbers (got " + std::to_string(value.size()) +
                                  " elements)"
                            : expected("an array of 3 numbers", value));
    return std::nullopt;
  }
  glm::dvec3 result;
  bool ok = true;
  for (int i = 0; i < 3; ++i) {
    const auto x = read_number(value[std::size_t(i)], child_pointer(pointer, std::size_t(i)), diag, range);
    if (x)
      result[i] = *x;
    else
      ok = false;
  }
  if (!ok) return std::nullopt;
  return result;
}

bool within_count_limit(std::size_t count, int64_t limit, std::string_view what,
                        std::string_view limit_name, const std::string& pointer, Diagnostics& diag) {
  if (count <= uint64_t(limit)) return true;
  diag.error(pointer, std::to_string(count) + " " + std::string(what) + " exceed the limit of " +
                          std::to_string(limit) + " (" + std::string(limit_name) + ")");
  return false;
}

ObjectReader::ObjectReader(const Json& value, std::string pointer, Diagnostics& diag)
    : pointer_(std::move(pointer)), diag_(diag) {
  if (value.is_object())
    object_ = &value;
  else
    diag_.error(pointer_, expected("an object", value));
}

bool ObjectReader::has(std::string_view key) const {
  return object_ && object_->find(key) != object_->end();
}

void ObjectReader::allow(std::initializer_list<std::string_view> keys) {
  for (std::string_view key : keys) known_.emplace(key);
}

const Json* ObjectReader::get(std::string_view key, Presence presence) {
  known_.emplace(key);
  if (!object_) return nullptr;
  const auto it = object_->find(key);
  if (it == object_->end()) {
    if (presence == Presence::kRequired) diag_.error(pointer_of(key), "required field is missing");
    return nullptr;
  }
  return &*it;
}

std::optional<double> ObjectReader::number(std::string_view key, const Range& range,
                                           Presence presence) {
  const Json* value = get(key, presence);
  return value ? read_number(*value, pointer_of(key), diag_, range) : std::nullopt;
}

std::optional<int64_t> ObjectReader::integer(std::string_view key, const Range& range,
                                             Presence presence) {
  const Json* value = get(key, presence);
  return value ? read_integer(*value, pointer_of(key), diag_, range) : std::nullopt;
}

std::optional<uint64_t> ObjectReader::unsigned_integer(std::string_view key, Presence presence) {
  const Json* value = get(key, presence);
  return value ? read_unsigned(*value, pointer_of(key), diag_) : std::nullopt;
}

std::optional<std::string> ObjectReader::string(std::string_view key, Presence presence) {
  const Json* value = get(key, presence);
  return value ? read_string(*value, pointer_of(key), diag_) : std::nullopt;
}

std::optional<glm::dvec3> ObjectReader::vec3(std::string_view key, const Range& range,
                                             Presence presence) {
  const Json* value = get(key, presence);
  return value ? read_vec3(*value, pointer_of(key), diag_, range) : std::nullopt;
}

const Json* ObjectReader::array(std::string_view key, Presence presence) {
  const Json* value = get(key, presence);
  if (value && !value->is_array()) {
    diag_.error(pointer_of(key), expected("an array", *value));
    return nullptr;
  }
  return value;
}

void ObjectReader::error(std::string_view key, std::string message) const {
  diag_.error(pointer_of(key), std::move(message));
}

void ObjectReader::warning(std::string_view key, std::string message) const {
  diag_.warning(pointer_of(key), std::move(message));
}

void ObjectReader::report_unknown_keys() const {
  if (!object_) return;
  const std::vector<std::string> candidates(known_.begin(), known_.end());
  for (const auto& [key, value] : object_->items()) {
    if (known_.count(key)) continue;
    diag_.error(pointer_of(key), "unknown field " + quote_user_string(key) + did_you_mean(key, candidates));
  }
}

}  // namespace penumbra::api
