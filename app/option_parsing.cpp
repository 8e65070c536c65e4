#include "app/option_parsing.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>

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

bool OptionParser::double_value(double lo, double hi, double* out) {
  std::string v;
  if (!value(&v)) return false;
  errno = 0;
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || errno == ERANGE || !(x >= lo && x <= hi)) {
    failed_ = true;
    error_ = current_ + " takes a number from " + std::to_string(lo) + " to " + std::to_string(hi);
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

bool OptionalOverrides::parse(OptionParser& p) {
  long long i;
  double d;
  std::string s;
  if (p.is("--spp")) {
    if (p.int_value(1, 1 << 24, &i)) spp = i;
  } else if (p.is("--width")) {
    if (p.int_value(1, 65536, &i)) width = i;
  } else if (p.is("--height")) {
    if (p.int_value(1, 65536, &i)) height = i;
  } else if (p.is("--seed")) {
    if (p.int_value(0, (1LL << 53), &i)) seed = i;
  } else if (p.is("--threads")) {
    if (p.int_value(0, 4096, &i)) threads = i;
  } else if (p.is("--max-depth")) {
    if (p.int_value(-1, 1 << 20, &i)) max_depth = i;
  } else if (p.is("--integrator")) {
    if (p.value(&s)) integrator = s;
  } else if (p.is("--time-limit")) {
    if (p.double_value(0, 1e9, &d)) time_limit = d;
  } else if (p.is("--noise-threshold")) {
    if (p.double_value(0, 1e9, &d)) noise_threshold = d;
  } else {
    return false;
  }
  return true;
}

std::string OptionalOverrides::apply(RenderSettings* s) const {
  if (spp) s->spp = int(*spp);
  if (width) s->width = int(*width);
  if (height) s->height = int(*height);
  if (seed) s->seed = uint64_t(*seed);
  if (threads) s->threads = int(*threads);
  if (max_depth) {
    if (*max_depth == 0) return "--max-depth must be >= 1 or -1 (unlimited)";
    s->max_depth = int(*max_depth);
  }
  if (integrator) {
    if (*integrator == "path") s->integrator = IntegratorKind::kPath;
    else if (*integrator == "distributed") s->integrator = IntegratorKind::kDistributed;
    else return "--integrator must be 'path' or 'distributed'";
  }
  if (time_limit) s->time_limit = *time_limit;
  if (noise_threshold) s->noise_threshold = float(*noise_threshold);
  return "";
}

}  // namespace penumbra::app
