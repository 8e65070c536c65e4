#include "api/json_document.h"

#include <set>
#include <string>
#include <vector>

#include <simdjson.h>

namespace penumbra::api {

namespace {

struct DepthExceeded {};

// Follows the parser's events to know the JSON pointer of the current position, which the
// callback is not given, so a duplicate key can be reported where it is.
class PathTracker {
 public:
  PathTracker(int max_depth, Diagnostics& diag) : max_depth_(max_depth), diag_(diag) {}

  bool on_event(int depth, Json::parse_event_t event, const Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        // `depth` counts the containers around this one; throwing is the only way to stop the
        // parser from a callback (returning false merely discards the value).
        if (depth >= max_depth_) throw DepthExceeded{};
        enter_value();
        frames_.push_back({event == Json::parse_event_t::array_start, 0, {}, {}});
        break;
      case Json::parse_event_t::key: {
        Frame& frame = frames_.back();
        frame.last_key = parsed.get<std::string>();
        if (!frame.keys.insert(frame.last_key).second)
          diag_.error(pointer() + "/" + escape_pointer_token(frame.last_key),
                      "duplicate key: an object must not name the same member twice");
        break;
      }
      case Json::parse_event_t::value:  // a scalar (containers end with *_end, not value)
        enter_scalar();
        break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        frames_.pop_back();
        if (!tokens_.empty() && tokens_.size() > frames_.size()) tokens_.pop_back();
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool is_array;
    std::size_t next_index;
    std::string last_key;
    std::set<std::string> keys;
  };

  // A scalar is a leaf, never part of a reported path: it only advances its array's index (no
  // token string per number: a mesh's inline arrays hold millions of them).
  void enter_scalar() {
    if (!frames_.empty() && frames_.back().is_array) ++frames_.back().next_index;
  }

  // A container begins inside the current container: remember its token.
  void enter_value() {
    if (frames_.empty()) return;
    Frame& parent = frames_.back();
    pending_token_ = parent.is_array ? std::to_string(parent.next_index++)
                                     : escape_pointer_token(parent.last_key);
    tokens_.resize(frames_.size() - 1);
    tokens_.push_back(pending_token_);
  }

  std::string pointer() const {
    std::string result;
    // tokens_[i] is the token of frames_[i + 1] inside frames_[i].
    for (std::size_t i = 0; i + 1 < frames_.size() && i < tokens_.size(); ++i)
      result += "/" + tokens_[i];
    return result;
  }

  int max_depth_;
  Diagnostics& diag_;
  std::vector<Frame> frames_;
  std::vector<std::string> tokens_;
  std::string pending_token_;
};

// nlohmann's messages start with "[json.exception.parse_error.101] " and may quote raw input
// bytes; keep them readable and valid UTF-8.
std::string clean_message(const std::string& what) {
  std::string text = what;
  if (!text.empty() && text[0] == '[') {
    const auto end = text.find("] ");
    if (end != std::string::npos) text.erase(0, end + 2);
  }
  constexpr std::size_t kMaxLength = 300;
  if (text.size() > kMaxLength) text = text.substr(0, kMaxLength) + "...";
  for (char& c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u >= 0x80 || u < 0x20) c = '?';
  }
  return text;
}

// simdjson's DOM (a fully validating parser: UTF-8, grammar, numbers correctly rounded) turned
// into the same nlohmann value the reference path builds, or false where this path cannot vouch for
// that: a duplicate key, nesting at the cap, a string that is not valid UTF-8 after unescaping.
// The caller then parses again with nlohmann, whose diagnostics stay the only ones users see.
class FastConverter {
 public:
  explicit FastConverter(int max_depth) : max_depth_(max_depth) {}

  bool convert(const simdjson::dom::element& element, Json& out, int depth) const {
    using Type = simdjson::dom::element_type;
    switch (element.type()) {
      case Type::ARRAY: {
        if (depth >= max_depth_) return false;
        const simdjson::dom::array array = element.get_array().value_unsafe();
        out = Json::array();
        auto& items = out.get_ref<Json::array_t&>();
        items.reserve(array.size());  // exact: no growth by doubling, as nlohmann's parser does
        for (const simdjson::dom::element child : array)
          if (!convert(child, items.emplace_back(), depth + 1)) return false;
        return true;
      }
      case Type::OBJECT: {
        if (depth >= max_depth_) return false;
        out = Json::object();
        auto& members = out.get_ref<Json::object_t&>();
        const simdjson::dom::object object = element.get_object().value_unsafe();
        for (const simdjson::dom::key_value_pair field : object) {
          if (!valid_utf8(field.key)) return false;
          const auto [slot, inserted] = members.try_emplace(std::string(field.key));
          if (!inserted || !convert(field.value, slot->second, depth + 1)) return false;
        }
        return true;
      }
      case Type::INT64: {
        // nlohmann keeps non-negative integers as unsigned (its "-0" aside, which reads as 0).
        const int64_t value = element.get_int64().value_unsafe();
        out = value < 0 ? Json(value) : Json(uint64_t(value));
        return true;
      }
      case Type::UINT64:
        out = element.get_uint64().value_unsafe();
        return true;
      case Type::DOUBLE:
        out = element.get_double().value_unsafe();
        return true;
      case Type::STRING: {
        const std::string_view text = element.get_string().value_unsafe();
        if (!valid_utf8(text)) return false;
        out = std::string(text);
        return true;
      }
      case Type::BOOL:
        out = element.get_bool().value_unsafe();
        return true;
      case Type::NULL_VALUE:
        out = nullptr;
        return true;
    }
    return false;
  }

 private:
  // simdjson checks the input's bytes; what an escape unescapes to is checked here. simdjson
  // 3.0.1 already rejects a lone surrogate ("\udc00"), as nlohmann does; this is for versions
  // that would substitute one.
  static bool valid_utf8(std::string_view text) {
    return simdjson::validate_utf8(text.data(), text.size());
  }

  int max_depth_;
};

void release_containers(Json& value) {
  if (value.is_array()) {
    auto& items = value.get_ref<Json::array_t&>();
    for (Json& item : items)
      if (item.is_structured()) release_containers(item);
    items.clear();
  } else if (value.is_object()) {
    auto& members = value.get_ref<Json::object_t&>();
    for (auto& member : members)
      if (member.second.is_structured()) release_containers(member.second);
    members.clear();
  }
}

}  // namespace

JsonDocument::~JsonDocument() {
  if (value) release_containers(*value);
}

std::optional<Json> parse_json_fast(std::string_view text, int max_depth) {
  simdjson::dom::parser parser;
  simdjson::dom::element root;
  // Copies the text into a padded buffer (simdjson reads up to 64 bytes past the end).
  if (parser.parse(text.data(), text.size(), /*realloc_if_needed=*/true).get(root)) return {};
  Json value;
  if (!FastConverter(max_depth).convert(root, value, 0)) return {};
  return value;
}

JsonDocument parse_json_document(std::string_view text, int max_depth, Diagnostics& diag) {
  // The fast path builds the value in under half the time of nlohmann's own parser (a 4 MB
  // inline mesh: docs/performance.md); anything it does not vouch for goes through nlohmann.
  if (auto value = parse_json_fast(text, max_depth)) {
    JsonDocument document;
    document.value = std::move(value);
    return document;
  }
  return parse_json_document_reference(text, max_depth, diag);
}

JsonDocument parse_json_document_reference(std::string_view text, int max_depth,
                                           Diagnostics& diag) {
  JsonDocument document;
  PathTracker tracker(max_depth, diag);
  try {
    document.value = Json::parse(
        text.begin(), text.end(),
        [&tracker](int depth, Json::parse_event_t event, Json& parsed) {
          return tracker.on_event(depth, event, parsed);
        },
        /*allow_exceptions=*/true, /*ignore_comments=*/false);
  } catch (const DepthExceeded&) {
    document.syntax_error = true;
    diag.error("", "JSON is nested deeper than the limit of " + std::to_string(max_depth) +
                       " levels (max_json_depth)");
  } catch (const Json::exception& e) {
    document.syntax_error = true;
    diag.error("", "invalid JSON: " + clean_message(e.what()));
  }
  if (document.syntax_error) document.value.reset();
  return document;
}

}  // namespace penumbra::api
