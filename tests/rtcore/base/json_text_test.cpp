// parse_json_text: syntax errors placed by line and column, and, for the inputs that ask, a key an
// object names twice refused by its path.
#include "rtcore/base/json_text.h"

#include <gtest/gtest.h>

namespace resecto {
namespace {

TEST(JsonText, SyntaxErrorsNameTheLineAndColumn) {
  const Result<nlohmann::json> bad = parse_json_text("{\n  \"a\": 1,\n  \"b\": }\n", "f.json");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().rfind("f.json: not valid JSON at line 3, column 8: ", 0), 0u) << bad.error();
}

// Audit 6, A: the library keeps a repeated key's last value without a word.
TEST(JsonText, RepeatedKeysAreRefusedByPathWhenAsked) {
  const std::string twice = R"({"a": {"b": [1, {"c": 1, "d": [{"e": 1, "e": 2}]}]}})";
  EXPECT_TRUE(parse_json_text(twice, "f.json"));  // the default keeps the library's reading
  const Result<nlohmann::json> refused = parse_json_text(twice, "f.json", true);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error(), "f.json: a.b[1].d[0].e: the key appears twice in its object");
  EXPECT_EQ(parse_json_text(R"({"x": 1, "y": 2, "x": 3})", "f.json", true).error(), "f.json: x: the key appears twice in its object");
  // A message stays one printable line whatever the key holds.
  EXPECT_EQ(parse_json_text(R"({"a\nb": 1, "a\nb": 2})", "f.json", true).error(), "f.json: a\\x0ab: the key appears twice in its object");
  // The same key in sibling objects, and in an object after an array of scalars, is no repetition.
  const Result<nlohmann::json> siblings =
      parse_json_text(R"({"p": [1, 2, {"k": 1}, {"k": 2}], "q": {"k": 3}, "r": [[1], {"k": [4]}]})", "f.json", true);
  ASSERT_TRUE(siblings) << siblings.error();
  EXPECT_EQ((*siblings)["r"][1]["k"][0], 4);
}

}  // namespace
// Audit 32, F1: any depth parses, but a document thousands of levels deep overflows the stack when it
// is copied or walked; brackets inside strings are text, not nesting.
TEST(JsonText, NestingPastTheLimitIsRefusedByWhereItGoesDeep) {
  const std::string deep = "{\"a\": " + std::string(300, '[') + std::string(300, ']') + "}";
  const Result<nlohmann::json> refused = parse_json_text(deep, "deep.json");
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error(), "deep.json: nests arrays and objects more than 256 levels deep at line 1, column 262");
  const std::string quoted = "{\"a\": \"" + std::string(300, '[') + "\\\"{\"}";
  EXPECT_TRUE(parse_json_text(quoted, "quoted.json")) << "brackets in a string";
  const std::string at_limit = std::string(255, '[') + std::string(255, ']');
  EXPECT_TRUE(parse_json_text("{\"a\": " + at_limit + "}", "limit.json"));
}

}  // namespace resecto
