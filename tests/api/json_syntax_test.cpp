// Text that is not JSON (or too deep) is a kSyntax error on pointer "", never a crash or hang.
#include <chrono>

#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

TEST(JsonSyntax, MalformedTextIsSyntaxError) {
  for (const char* text : {"", "{", "{\"version\": 1,}", "nul", "{\"a\" 1}", "[1, 2", "\"abc"}) {
    const LoadResult r = load_scene(text);
    EXPECT_EQ(r.kind, LoadErrorKind::kSyntax) << text;
    ASSERT_EQ(r.errors.size(), 1u) << text;
    EXPECT_EQ(r.errors[0].pointer, "");
    EXPECT_NE(r.errors[0].message.find("invalid JSON"), std::string::npos);
    EXPECT_FALSE(r.request);
  }
}

TEST(JsonSyntax, NumberOverflowIsSyntaxError) {
  const LoadResult r = load_scene(R"({"version": 1, "render": {"spp": 1e400}})");
  EXPECT_EQ(r.kind, LoadErrorKind::kSyntax);
  EXPECT_TRUE(has(r.errors, "", "overflow")) << describe(r.errors);
}

TEST(JsonSyntax, InvalidUtf8IsSyntaxErrorWithCleanMessage) {
  const LoadResult r = load_scene("{\"version\": \"\xff\xfe\"}");
  EXPECT_EQ(r.kind, LoadErrorKind::kSyntax);
  ASSERT_FALSE(r.errors.empty());
  for (char c : r.errors[0].message) EXPECT_LT(static_cast<unsigned char>(c), 0x80);
}

TEST(JsonSyntax, CommentsAreNotJson) {
  EXPECT_EQ(load_scene("{\"version\": 1 /* v1 */}").kind, LoadErrorKind::kSyntax);
}

TEST(JsonSyntax, HundredThousandNestedArraysFailFast) {
  const std::string text(100000, '[');
  const auto start = std::chrono::steady_clock::now();
  const LoadResult r = load_scene(text);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.kind, LoadErrorKind::kSyntax);
  EXPECT_TRUE(has(r.errors, "", "nested deeper than the limit of 64")) << describe(r.errors);
  EXPECT_LT(seconds, 1.0);
}

TEST(JsonSyntax, ClosedDeepNestingAlsoCapped) {
  const std::string text = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_EQ(load_scene(text).kind, LoadErrorKind::kSyntax);
  const std::string objects = [] {
    std::string s;
    for (int i = 0; i < 50000; ++i) s += "{\"a\":";
    s += "1";
    for (int i = 0; i < 50000; ++i) s += "}";
    return s;
  }();
  EXPECT_EQ(load_scene(objects).kind, LoadErrorKind::kSyntax);
}

TEST(JsonSyntax, DepthLimitBoundary) {
  Limits limits;
  limits.max_json_depth = 10;
  // 10 nested containers are JSON within the cap: the error is about the scene, not syntax.
  const LoadResult at_limit = load_scene(std::string(10, '[') + std::string(10, ']'), limits);
  EXPECT_EQ(at_limit.kind, LoadErrorKind::kInvalid);
  EXPECT_TRUE(has(at_limit.errors, "", "must be an object")) << describe(at_limit.errors);
  const LoadResult over = load_scene(std::string(11, '[') + std::string(11, ']'), limits);
  EXPECT_EQ(over.kind, LoadErrorKind::kSyntax);
  EXPECT_TRUE(has(over.errors, "", "limit of 10")) << describe(over.errors);
}

TEST(JsonSyntax, DefaultDepthAdmitsEveryValidScene) {
  // A scene needs at most 5 levels (root / objects / object / transform / rotate / axis).
  Json scene = base_scene();
  scene["objects"][0]["transform"] = {{"rotate", {{"axis", {0, 1, 0}}, {"degrees", 10}}}};
  EXPECT_LOADS(load(scene));
}

TEST(JsonSyntax, RootMustBeAnObject) {
  const LoadResult r = load_scene("[1, 2, 3]");
  EXPECT_EQ(r.kind, LoadErrorKind::kInvalid);
  EXPECT_ERROR(r, "", "must be an object (got an array)");
}

TEST(JsonSyntax, DuplicateKeysAreErrorsWithPointer) {
  const LoadResult r = load_scene(R"({
    "version": 1,
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 30, "fov": 50},
    "materials": {"a/b": {"type": "diffuse", "type": "diffuse"}},
    "objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, "material": "a/b"},
                {"type": "sphere", "radius": 1, "radius": 2, "center": [0,0,0], "material": "a/b"}]
  })");
  EXPECT_EQ(r.kind, LoadErrorKind::kInvalid);
  EXPECT_ERROR(r, "/camera/fov", "duplicate key");
  EXPECT_ERROR(r, "/materials/a~1b/type", "duplicate key");
  EXPECT_ERROR(r, "/objects/1/radius", "duplicate key");
  EXPECT_EQ(r.errors.size(), 3u) << describe(r.errors);
}

TEST(JsonSyntax, DuplicateKeyPointersCountTheScalarsBeforeThem) {
  // Scalars in an array take no token of their own but advance its index.
  const LoadResult r = load_scene(
      R"({"version": 1, "x": [1, 2, [3, {"a": 1, "a": 2}]], "y": {"b": [0, {"c": 1, "c": 2}]}})");
  EXPECT_ERROR(r, "/x/2/1/a", "duplicate key");
  EXPECT_ERROR(r, "/y/b/1/c", "duplicate key");
}

TEST(JsonSyntax, GarbageBytesNeverCrash) {
  std::string text = base_scene().dump();
  // Every truncation of a valid scene is handled.
  for (std::size_t n = 0; n < text.size(); n += 7) {
    const LoadResult r = load_scene(std::string_view(text).substr(0, n));
    EXPECT_FALSE(r.ok());
  }
}

}  // namespace
}  // namespace penumbra::test
