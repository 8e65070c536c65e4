#include "api/render_overrides.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <string>

namespace penumbra::api {

namespace {

struct RenderFlag {
  std::string_view flag;
  std::string_view member;  // of the "render" block
  bool text;                // the member is a string: the flag's text is taken as it is
  bool list = false;        // the member is an array of strings: the text is split at commas
  bool numbers = false;     // with list: the items are numbers, read as JSON scalars
};

constexpr std::array<RenderFlag, 15> kRenderFlags = {{
    {"--width", "width", false},
    {"--height", "height", false},
    {"--spp", "spp", false},
    {"--max-depth", "max_depth", false},
    {"--rr-depth", "rr_depth", false},
    {"--integrator", "integrator", true},
    {"--sampler", "sampler", true},
    {"--path-reuse", "path_reuse", false},
    {"--seed", "seed", false},
    {"--noise-threshold", "noise_threshold", false},
    {"--time-limit", "time_limit", false},
    {"--outputs", "outputs", false, true},
    {"--aov", "outputs", false, true},  // the name Cycles and Mitsuba users look for
    {"--denoise", "denoise", false},    // a switch: "--denoise" alone is "--denoise true"
    {"--window", "window", false, true, true},  // "--window 0,0,64,32" is [0, 0, 64, 32]
}};

constexpr std::array<std::string_view, kRenderFlags.size() + 1> kAllFlags = [] {
  std::array<std::string_view, kRenderFlags.size() + 1> flags{};
  for (std::size_t i = 0; i < kRenderFlags.size(); ++i) flags[i] = kRenderFlags[i].flag;
  flags.back() = kThreadsFlag;
  return flags;
}();

const RenderFlag* find_render_flag(std::string_view flag) {
  const auto it = std::find_if(kRenderFlags.begin(), kRenderFlags.end(),
                               [&](const RenderFlag& f) { return f.flag == flag; });
  return it == kRenderFlags.end() ? nullptr : &*it;
}

}  // namespace

std::span<const std::string_view> render_override_flags() { return kAllFlags; }

bool is_switch_override_flag(std::string_view flag) { return flag == "--denoise"; }

bool is_render_override_flag(std::string_view flag) {
  return std::find(kAllFlags.begin(), kAllFlags.end(), flag) != kAllFlags.end();
}

Json override_value(const RenderOverride& override_flag) {
  const std::string& text = override_flag.value;
  const RenderFlag* f = find_render_flag(override_flag.flag);
  if (f && f->list) {
    // "albedo,normal" -> ["albedo", "normal"]; "" -> [] (no layers). Each item is checked by the
    // field's parser; the count is bounded there before any item is read.
    Json items = Json::array();
    size_t start = 0;
    while (!text.empty() && start <= text.size()) {
      const size_t comma = std::min(text.find(',', start), text.size());
      const std::string item = text.substr(start, comma - start);
      items.push_back(f->numbers ? override_value(RenderOverride{"", item}) : Json(item));
      start = comma + 1;
    }
    return items;
  }
  // Containers are never a flag's value; not parsing them also keeps a hostile argument from
  // building a deeply nested document.
  if ((f && f->text) || text.find_first_of("[{") != std::string::npos) return text;
  try {
    Json value = Json::parse(text);
    if (value.is_primitive()) return value;
  } catch (const Json::out_of_range&) {
    // A number too large for a double (1e400): still a number, which the field's check rejects
    // as out of range rather than as a string.
    return std::strtod(text.c_str(), nullptr);
  } catch (const Json::exception&) {
    // Not JSON at all ("abc", "0x10"): the value is the text, a string.
  }
  return text;
}

std::optional<int> read_thread_count(const Json& value, Diagnostics& diag) {
  Diagnostics own;
  const auto threads = read_integer(value, "", own, Range::closed(0, kMaxThreads));
  for (Diagnostic& d : own.take_errors()) {
    d.flag = kThreadsFlag;
    diag.error(std::move(d));
  }
  return threads ? std::optional<int>(int(*threads)) : std::nullopt;
}

std::optional<int> apply_render_overrides(Json& document, std::span<const RenderOverride> overrides,
                                          Diagnostics& diag) {
  const RenderOverride* threads = nullptr;
  for (const RenderOverride& o : overrides) {
    if (o.flag == kThreadsFlag) {
      threads = &o;
      continue;
    }
    const RenderFlag* f = find_render_flag(o.flag);
    if (!f) {
      diag.error(Diagnostic{"", "is not a flag of the render block", o.flag});
      continue;
    }
    if (!document.is_object()) continue;
    if (!document.contains("render")) document["render"] = Json::object();
    Json& render = document["render"];
    if (!render.is_object()) continue;
    render[std::string(f->member)] = override_value(o);
    diag.attribute_to_flag(child_pointer("/render", f->member), o.flag);
  }
  return threads ? read_thread_count(override_value(*threads), diag) : std::nullopt;
}

}  // namespace penumbra::api
