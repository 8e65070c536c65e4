#pragma once
// The fast JSON path's promise, as one check for tests/api/json_document_test.cpp and the fuzz
// target json_document: the value it builds is the one nlohmann's parser builds.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "api/diagnostics.h"
#include "api/json_reader.h"

namespace penumbra::api {

// Equal values with equal types, recursively; the one difference allowed is the zero of "-0"
// (nlohmann: number_integer 0, the fast path: number_unsigned 0). Floats compare by bits, so
// -0.0 against 0.0 or a rounding difference fails.
inline bool json_same_value(const Json& a, const Json& b, std::string& where,
                            const std::string& at = "") {
  const auto fail = [&](const std::string& why) {
    where = (at.empty() ? "/" : at) + ": " + why + " (" + a.dump() + " vs " + b.dump() + ")";
    return false;
  };
  const bool zeros = a.is_number_integer() && b.is_number_integer() &&
                     a.get<int64_t>() == 0 && b.get<int64_t>() == 0;
  if (a.type() != b.type() && !zeros) return fail("types differ");
  switch (a.type()) {
    case Json::value_t::array:
      if (a.size() != b.size()) return fail("sizes differ");
      for (std::size_t i = 0; i < a.size(); ++i)
        if (!json_same_value(a[i], b[i], where, at + "/" + std::to_string(i))) return false;
      return true;
    case Json::value_t::object: {
      if (a.size() != b.size()) return fail("member counts differ");
      for (auto it = a.begin(); it != a.end(); ++it) {
        const auto other = b.find(it.key());
        if (other == b.end()) return fail("member " + it.key() + " missing");
        if (!json_same_value(it.value(), *other, where, at + "/" + it.key())) return false;
      }
      return true;
    }
    case Json::value_t::number_float: {
      const double x = a.get<double>(), y = b.get<double>();
      if (std::signbit(x) != std::signbit(y) || !(x == y)) return fail("floats differ");
      return true;
    }
    default:
      return a == b || zeros ? true : fail("values differ");
  }
}

// The same errors in the same order, pointer and message alike (where a deferred text's
// diagnostics must be the reference's); on a difference, `where` says which.
inline bool json_same_errors(Diagnostics a, Diagnostics b, std::string& where) {
  const std::vector<Diagnostic> x = a.take_errors(), y = b.take_errors();
  if (x.size() != y.size()) {
    where = std::to_string(x.size()) + " errors against " + std::to_string(y.size());
    return false;
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i].pointer != y[i].pointer || x[i].message != y[i].message) {
      where = "error " + std::to_string(i) + ": " + x[i].pointer + " " + x[i].message +
              " against " + y[i].pointer + " " + y[i].message;
      return false;
    }
  }
  return true;
}

}  // namespace penumbra::api
