// The Idempotency-Key header at its boundaries: absent, quoted, 255 and 256 characters.
#include "server/http/idempotency_key.h"

#include <gtest/gtest.h>

namespace penumbra::test {
namespace {

using server::parse_idempotency_key;
using server::Problem;

bool refused(const std::string& header) {
  return std::holds_alternative<Problem>(parse_idempotency_key(header));
}

TEST(IdempotencyKey, ParsedForms) {
  EXPECT_EQ(std::get<std::string>(parse_idempotency_key(std::nullopt)), "") << "no header, no key";
  EXPECT_EQ(std::get<std::string>(parse_idempotency_key("order-42")), "order-42");
  EXPECT_EQ(std::get<std::string>(parse_idempotency_key(" \"order-42\"\t")), "order-42");
  EXPECT_EQ(std::get<std::string>(parse_idempotency_key(std::string(255, 'k'))),
            std::string(255, 'k'));
}

TEST(IdempotencyKey, RefusedForms) {
  EXPECT_TRUE(refused(std::string(256, 'k'))) << "limit + 1";
  EXPECT_TRUE(refused(""));
  EXPECT_TRUE(refused("\"\""));
  EXPECT_TRUE(refused("two words"));
  EXPECT_TRUE(refused("caf\xc3\xa9"));
  const Problem p = std::get<Problem>(parse_idempotency_key("a b"));
  EXPECT_EQ(p.status, 400);
  EXPECT_EQ(p.type, "urn:penumbra:problem:invalid-idempotency-key");
}

}  // namespace
}  // namespace penumbra::test
