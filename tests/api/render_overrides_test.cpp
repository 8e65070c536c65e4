// The CLI's render flags are checked by the JSON fields' own code and limits, and their errors
// read as the JSON field's would, naming the flag (api/render_overrides.h).
#include "api/render_overrides.h"

#include <algorithm>
#include <string>
#include <vector>

#include "api/embedded_documents.h"
#include "tests/api/scene_test_util.h"

namespace penumbra::test {
namespace {

LoadResult load_with(const std::vector<RenderOverride>& overrides, const Json& scene = base_scene()) {
  return load_scene(scene.dump(), {}, overrides);
}

// The first error of a load with this one flag, as the CLI prints it.
std::string first_error(const std::string& flag, const std::string& text) {
  const LoadResult r = load_with({{flag, text}});
  return r.errors.empty() ? "(no error)" : r.errors[0].to_string();
}

const Diagnostic* find_error(const LoadResult& r, const std::string& pointer) {
  for (const Diagnostic& d : r.errors)
    if (d.pointer == pointer) return &d;
  return nullptr;
}

// The flag's message for `text` must be the message of the JSON field set to the value the text
// stands for, with the flag named.
void expect_same_message_as_json(const std::string& flag, const std::string& text) {
  const RenderOverride o{flag, text};
  std::string member = flag.substr(2);  // "--max-depth" -> "max_depth"
  std::replace(member.begin(), member.end(), '-', '_');
  const std::string pointer = "/render/" + member;
  Json scene = base_scene();
  scene["render"][member] = override_value(o);
  const LoadResult from_json = load(scene);
  const LoadResult from_flag = load_with({o});
  const Diagnostic* json_error = find_error(from_json, pointer);
  const Diagnostic* flag_error = find_error(from_flag, pointer);
  ASSERT_NE(json_error, nullptr) << flag << " " << text << ":\n" << describe(from_json.errors);
  ASSERT_NE(flag_error, nullptr) << flag << " " << text << ":\n" << describe(from_flag.errors);
  EXPECT_FALSE(from_flag.ok());
  EXPECT_EQ(flag_error->message, json_error->message) << flag << " " << text;
  EXPECT_EQ(flag_error->flag, flag);
  EXPECT_TRUE(json_error->flag.empty());
  EXPECT_EQ(flag_error->to_string(), flag + " (" + pointer + "): " + json_error->message);
}

// Each flag at its bounds: the last accepted value and the first rejected one.
struct Boundary {
  std::string flag;
  std::string accepted;
  std::string rejected;
};

const std::vector<Boundary> kBoundaries = {
    {"--width", "8192", "8193"},          {"--width", "1", "0"},
    {"--height", "8192", "8193"},         {"--height", "1", "0"},
    {"--spp", "1048576", "1048577"},      {"--spp", "1", "0"},
    {"--max-depth", "1024", "1025"},      {"--max-depth", "-1", "0"},
    {"--rr-depth", "1024", "1025"},       {"--rr-depth", "1", "0"},
    {"--seed", "18446744073709551615", "18446744073709551616"},
    {"--seed", "0", "-1"},                {"--time-limit", "86400", "86401"},
    {"--time-limit", "0", "-1"},          {"--noise-threshold", "1e30", "1e31"},
    {"--noise-threshold", "0", "-1"},     {"--integrator", "distributed", "distributd"},
};

TEST(RenderOverrides, EachFlagAtItsLimitAndOnePast) {
  for (const Boundary& b : kBoundaries) {
    EXPECT_LOADS(load_with({{b.flag, b.accepted}}));
    expect_same_message_as_json(b.flag, b.rejected);
  }
}

TEST(RenderOverrides, ValuesReachTheSettings) {
  const LoadResult r = load_with({{"--width", "320"}, {"--height", "200"}, {"--spp", "3"},
                                  {"--max-depth", "-1"}, {"--rr-depth", "2"},
                                  {"--integrator", "distributed"}, {"--seed", "18446744073709551615"},
                                  {"--noise-threshold", "0.05"}, {"--time-limit", "2.5"},
                                  {"--threads", "7"}});
  EXPECT_LOADS(r);
  const RenderSettings& s = r.request->settings;
  EXPECT_EQ(s.width, 320);
  EXPECT_EQ(s.height, 200);
  EXPECT_EQ(s.spp, 3);
  EXPECT_EQ(s.max_depth, -1);
  EXPECT_EQ(s.rr_depth, 2);
  EXPECT_EQ(s.integrator, IntegratorKind::kDistributed);
  EXPECT_EQ(s.seed, 18446744073709551615ull);
  EXPECT_FLOAT_EQ(s.noise_threshold, 0.05f);
  EXPECT_DOUBLE_EQ(s.time_limit, 2.5);
  EXPECT_EQ(s.threads, 7);
}

TEST(RenderOverrides, BadTypesGetTheJsonFieldsMessage) {
  const std::vector<std::string> not_numbers = {"abc", "true", "null", "", "[1]", "0x10"};
  for (const char* flag : {"--width", "--height", "--spp", "--max-depth", "--rr-depth", "--seed",
                           "--time-limit", "--noise-threshold"})
    for (const std::string& text : not_numbers) expect_same_message_as_json(flag, text);
  for (const char* flag : {"--width", "--height", "--spp", "--max-depth", "--rr-depth", "--seed"})
    expect_same_message_as_json(flag, "2.5");
  expect_same_message_as_json("--integrator", "5");
}

// JSON text cannot hold 1e400 (nlohmann calls it a syntax error); as a flag it is a number out
// of range, as JSON documents built in code already report it.
TEST(RenderOverrides, NumbersBeyondDoubleAreOutOfRange) {
  EXPECT_EQ(first_error("--width", "1e400"), "--width (/render/width): must be an integer");
  EXPECT_EQ(first_error("--time-limit", "-1e400"),
            "--time-limit (/render/time_limit): must be a finite number of magnitude <= 1e+30");
}

TEST(RenderOverrides, ExactMessages) {
  const LoadResult r = load_with({{"--width", "65536"}, {"--height", "65536"}});
  ASSERT_EQ(r.errors.size(), 2u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].to_string(), "--width (/render/width): must be <= 8192 (max_width)");
  EXPECT_EQ(r.errors[1].to_string(), "--height (/render/height): must be <= 8192 (max_height)");
  EXPECT_EQ(first_error("--width", "abc"),
            "--width (/render/width): must be an integer (got a string)");
  EXPECT_EQ(first_error("--width", "2.5"), "--width (/render/width): must be an integer");
}

TEST(RenderOverrides, TotalPixelLimitAppliesToFlags) {
  const LoadResult at_limit = load_with({{"--width", "8192"}, {"--height", "2048"}});
  EXPECT_LOADS(at_limit);
  EXPECT_EQ(int64_t(at_limit.request->settings.width) * at_limit.request->settings.height,
            Limits{}.max_pixels);
  EXPECT_ERROR(load_with({{"--width", "8192"}, {"--height", "2049"}}), "/render", "(max_pixels)");
  // One flag, one JSON field: the cross-field check sees both.
  Json scene = base_scene();
  scene["render"]["height"] = 4096;
  EXPECT_ERROR(load_with({{"--width", "4097"}}, scene), "/render", "(max_pixels)");
}

TEST(RenderOverrides, ThreadsLimitAndOnePast) {
  for (const char* ok : {"0", "1", "4096"}) EXPECT_LOADS(load_with({{"--threads", ok}}));
  for (const auto& [text, message] : std::vector<std::pair<std::string, std::string>>{
           {"4097", "must be in [0, 4096]"},
           {"-1", "must be in [0, 4096]"},
           {"2.5", "must be an integer"},
           {"abc", "must be an integer (got a string)"},
           {"", "must be an integer (got a string)"}}) {
    const LoadResult r = load_with({{"--threads", text}});
    ASSERT_EQ(r.errors.size(), 1u) << text << "\n" << describe(r.errors);
    EXPECT_EQ(r.errors[0].to_string(), "--threads: " + message) << text;
  }
  Diagnostics diag;
  EXPECT_EQ(read_thread_count(Json(kMaxThreads), diag), kMaxThreads);
  EXPECT_EQ(read_thread_count(Json(kMaxThreads + 1), diag), std::nullopt);
  EXPECT_EQ(diag.error_count(), 1u);
}

TEST(RenderOverrides, ReplaceTheJsonValueAndTheLastFlagWins) {
  Json scene = base_scene();
  scene["render"] = {{"width", "not a number"}, {"spp", 0}};
  const LoadResult r = load_with({{"--width", "99999"}, {"--width", "64"}}, scene);
  // The JSON's width was replaced; its spp error stays the JSON's, not a flag's.
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].to_string(), "/render/spp: must be >= 1");
  scene["render"]["spp"] = 4;
  const LoadResult fixed = load_with({{"--width", "99999"}, {"--width", "64"}}, scene);
  EXPECT_LOADS(fixed);
  EXPECT_EQ(fixed.request->settings.width, 64);
}

TEST(RenderOverrides, DuplicateKeyInTheJsonStaysAboutTheJson) {
  const std::string text = R"({"version": 1, "render": {"width": 8, "width": 9},
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]}})";
  const LoadResult r = load_scene(text, {}, std::vector<RenderOverride>{{"--width", "16"}});
  const Diagnostic* d = find_error(r, "/render/width");
  ASSERT_NE(d, nullptr) << describe(r.errors);
  EXPECT_TRUE(d->flag.empty());
}

TEST(RenderOverrides, RenderThatIsNotAnObjectIsReportedOnce) {
  Json scene = base_scene();
  scene["render"] = 5;
  const LoadResult r = load_with({{"--width", "64"}}, scene);
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].to_string(), "/render: must be an object (got a number)");
}

TEST(RenderOverrides, UnknownFlagIsAnError) {
  EXPECT_FALSE(is_render_override_flag("--output"));
  EXPECT_EQ(first_error("--bogus", "1"), "--bogus: is not a flag of the render block");
}

TEST(RenderOverrides, WithoutFlagsTheLoadIsUnchanged) {
  Json scene = base_scene();
  scene["render"] = {{"width", 65536}};
  const LoadResult r = load(scene);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].to_string(), "/render/width: must be <= 8192 (max_width)");
  EXPECT_TRUE(r.errors[0].flag.empty());
}

// --aov a,b is the list ["a", "b"], checked by the field's own code: errors name the flag and
// the item's pointer; "" is no layer; the last flag wins.
TEST(RenderOverrides, AovIsACommaSeparatedList) {
  LoadResult r = load_with({{"--aov", "depth,albedo"}});
  EXPECT_LOADS(r);
  EXPECT_EQ(r.request->settings.outputs, uint32_t(kOutputDepth | kOutputAlbedo));
  r = load_with({{"--outputs", "normal"}});
  EXPECT_LOADS(r);
  EXPECT_EQ(r.request->settings.outputs, uint32_t(kOutputNormal));
  Json scene = base_scene();
  scene["render"]["outputs"] = {"albedo"};
  r = load_with({{"--aov", ""}}, scene);
  EXPECT_LOADS(r);
  EXPECT_EQ(r.request->settings.outputs, 0u);
  EXPECT_EQ(first_error("--aov", "albedo,nrmal"),
            "--aov (/render/outputs/1): unknown output layer 'nrmal' (did you mean 'normal'?); "
            "expected \"albedo\", \"normal\" or \"depth\"");
  EXPECT_EQ(first_error("--aov", "depth,depth"),
            "--aov (/render/outputs/1): output layer 'depth' is listed twice");
  EXPECT_EQ(first_error("--aov", "albedo,,normal"),
            "--aov (/render/outputs/1): unknown output layer ''; "
            "expected \"albedo\", \"normal\" or \"depth\"");
  EXPECT_EQ(first_error("--aov", "a,b,c,d"),
            "--aov (/render/outputs): 4 outputs exceed the limit of 3 (the number of output layers)");
}

// Every member of the "render" block in the scene schema has its flag, and only those (plus
// --threads) are flags.
TEST(RenderOverrides, OneFlagPerRenderMember) {
  const std::string* text = embedded_document("scene.schema.json");
  ASSERT_NE(text, nullptr);
  const Json members = Json::parse(*text)["$defs"]["render"]["properties"];
  std::vector<std::string> expected;
  for (const auto& [member, schema] : members.items()) {
    std::string flag = "--" + member;
    for (char& c : flag)
      if (c == '_') c = '-';
    expected.push_back(flag);
    EXPECT_TRUE(is_render_override_flag(flag)) << flag;
  }
  expected.push_back(std::string(kThreadsFlag));
  EXPECT_TRUE(is_render_override_flag("--aov"));  // the alias of --outputs
  EXPECT_EQ(render_override_flags().size(), expected.size() + 1);
}

}  // namespace
}  // namespace penumbra::test
