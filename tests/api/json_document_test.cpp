// parse_json_document's two parsers: simdjson's fast path must build exactly the value nlohmann's
// reference builds, and defer to it wherever it cannot (so every diagnostic stays nlohmann's).
#include "api/json_document.h"
#include "fuzz/json_same_value.h"

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace penumbra::api {
namespace {

struct Outcome {
  JsonDocument document;
  Diagnostics diagnostics;
};

Outcome reference(std::string_view text, int max_depth) {
  Outcome o;
  o.document = parse_json_document_reference(text, max_depth, o.diagnostics);
  return o;
}

// The fast path took `text`: it must agree with the reference, which must accept it silently.
void expect_fast_matches_reference(std::string_view text, int max_depth = 64) {
  SCOPED_TRACE(std::string(text.substr(0, 200)));
  const std::optional<Json> fast = parse_json_fast(text, max_depth);
  ASSERT_TRUE(fast.has_value()) << "the fast path deferred";
  const Outcome ref = reference(text, max_depth);
  ASSERT_TRUE(ref.document.value.has_value());
  EXPECT_FALSE(ref.diagnostics.has_errors());
  std::string where;
  EXPECT_TRUE(json_same_value(*ref.document.value, *fast, where)) << where;
}

TEST(JsonDocument, FastPathBuildsTheReferenceValue) {
  for (const char* text : {
           R"({"version": 1, "camera": {"fov": 40.5, "position": [0, -1.25, 3e2]}})",
           R"([0, -0, 1, -1, 9223372036854775807, 9223372036854775808, -9223372036854775808])",
           R"([18446744073709551615, 0.1, 1E2, 1e-2, -0.0, 0.0, 5e-324, 2.2250738585072011e-308])",
           R"([1e-400, -1e-400, 1.7976931348623157e308, 123456789012345678, 0.30000000000000004])",
           R"([3.141592653589793238462643383279502884197169399375105820974944592307816406286])",
           R"(["", "a\"b\\c\/d\b\f\n\r\t", "\u00e9\u4e2d", "\ud83d\ude00", "\u0000", "é中😀"])",
           R"({"": 1, "a/b": {"~": [true, false, null]}, "k": {}})", "[]", "{}", "\"s\"", "0",
           "-7", "true", "null", " \t\r\n[ 1 , 2 ] \n",
       })
    expect_fast_matches_reference(text);
}

TEST(JsonDocument, FastPathTakesAnInlineMesh) {
  std::ifstream file(std::string(PENUMBRA_SOURCE_DIR) + "/tests/accuracy/scenes/mesh_100k.json",
                     std::ios::binary);
  ASSERT_TRUE(file);
  std::stringstream text;
  text << file.rdbuf();
  expect_fast_matches_reference(text.str());
}

// Where the fast path defers, parse_json_document must give exactly the reference's result.
TEST(JsonDocument, FastPathDefersWhereTheReferenceReports) {
  struct Case {
    std::string text;
    int max_depth;
  };
  const std::vector<Case> cases = {
      {R"({"a": 1, "a": 2})", 64},                      // duplicate key
      {R"({"x": [{"b": 1, "c": 2, "b": 3}]})", 64},     // nested duplicate key
      {"[[[1]]]", 2},                                   // containers past the cap
      {R"({"a": {"b": {}}})", 2},
      {R"(["\ud800"])", 64},                            // lone high surrogate
      {R"(["\udc00"])", 64},                            // lone low surrogate
      {R"({"\ud800x": 1})", 64},                        // ... in a key
      {"[18446744073709551616]", 64},                   // beyond 64 bits: nlohmann takes a float
      {"[-9223372036854775809]", 64},
      {"[100000000000000000000000000000]", 64},
      {"[1e400]", 64},                                  // out of range: nlohmann reports it
      {"{} x", 64},
      {"[1,]", 64},
      {"", 64},
      {"\xef\xbb\xbf[1]", 64},                          // a byte-order mark
      {std::string("[1]\0", 4), 64},
      {"[\"\xff\"]", 64},
      {"[01]", 64},
      {"{\"a\":1 /* c */}", 64},
      {std::string(2000, '[') + std::string(2000, ']'), 4000},  // deeper than simdjson's 1024
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text.substr(0, 60));
    EXPECT_FALSE(parse_json_fast(c.text, c.max_depth).has_value()) << "the fast path took it";
    Diagnostics got_diag;
    const JsonDocument got = parse_json_document(c.text, c.max_depth, got_diag);
    const Outcome ref = reference(c.text, c.max_depth);
    EXPECT_EQ(got.syntax_error, ref.document.syntax_error);
    ASSERT_EQ(got.value.has_value(), ref.document.value.has_value());
    if (got.value) {
      EXPECT_EQ(*got.value, *ref.document.value);
    }
    std::string where;
    EXPECT_TRUE(json_same_errors(got_diag, ref.diagnostics, where)) << where;
  }
}

TEST(JsonDocument, DepthCapCountsContainersAsTheReferenceDoes) {
  // Two levels of containers under a cap of 2: accepted by both; a third is refused by both.
  expect_fast_matches_reference(R"({"a": [1, {"b": 2}]})", 3);
  expect_fast_matches_reference("[[1]]", 2);
  EXPECT_FALSE(parse_json_fast("[[[1]]]", 2).has_value());
  Diagnostics diag;
  EXPECT_TRUE(parse_json_document("[[[1]]]", 2, diag).syntax_error);
}

// nlohmann reads "-0" as number_integer 0, the fast path as number_unsigned 0: the readers must
// not tell them apart (a seed of -0 is the seed 0 whichever parser read it).
TEST(JsonDocument, MinusZeroReadsAsZeroFromEitherParser) {
  for (const Json& zero : {Json::parse("-0"), *parse_json_fast("-0", 64)}) {
    Diagnostics diag;
    EXPECT_EQ(read_unsigned(zero, "/render/seed", diag), std::optional<uint64_t>(0));
    EXPECT_EQ(read_integer(zero, "/render/spp", diag), std::optional<int64_t>(0));
    EXPECT_FALSE(diag.has_errors());
  }
}

}  // namespace
}  // namespace penumbra::api
