// libFuzzer target: the scene parser's two JSON parsers against each other
// (api/json_document.h). The first byte picks the nesting cap, the rest is the text. Wherever
// simdjson's fast path takes a text, nlohmann's reference must accept it without a diagnostic
// and build the same value (types included); wherever the fast path defers,
// parse_json_document must be the reference, diagnostics and all. Any disagreement aborts.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "api/json_document.h"
#include "fuzz/json_same_value.h"

namespace {

using penumbra::api::Diagnostics;
using penumbra::api::JsonDocument;

[[noreturn]] void disagree(const std::string& what) {
  std::fprintf(stderr, "json_document: the two parsers disagree: %s\n", what.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int max_depth = 1 + data[0] % 80;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);

  Diagnostics reference_diag;
  const JsonDocument reference =
      penumbra::api::parse_json_document_reference(text, max_depth, reference_diag);
  const auto fast = penumbra::api::parse_json_fast(text, max_depth);
  if (fast) {
    if (!reference.value || reference_diag.has_errors())
      disagree("the fast path took a text the reference reports");
    std::string where;
    if (!penumbra::api::json_same_value(*reference.value, *fast, where)) disagree(where);
  }
  Diagnostics combined_diag;
  const JsonDocument combined = penumbra::api::parse_json_document(text, max_depth, combined_diag);
  if (combined.syntax_error != reference.syntax_error ||
      combined.value.has_value() != reference.value.has_value())
    disagree("parse_json_document's verdict is not the reference's");
  if (!fast) {
    if (combined.value && *combined.value != *reference.value)
      disagree("a deferred text's value is not the reference's");
    std::string where;
    if (!penumbra::api::json_same_errors(combined_diag, reference_diag, where))
      disagree("a deferred text's diagnostics are not the reference's: " + where);
  }
  return 0;
}
