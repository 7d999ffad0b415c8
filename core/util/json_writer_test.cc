#include "core/util/json_writer.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>

#include "core/util/error.h"

namespace pkslam {
namespace {

TEST(JsonQuote, EscapesQuotesBackslashesAndControlCharacters) {
  EXPECT_EQ(JsonQuote("plain"), "\"plain\"");
  EXPECT_EQ(JsonQuote("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(JsonQuote("line\nnext\ttab\r"), "\"line\\nnext\\ttab\\r\"");
  EXPECT_EQ(JsonQuote(std::string_view("\x01\x1f", 2)), "\"\\u0001\\u001f\"");
  EXPECT_EQ(JsonQuote(std::string_view("nul\0x", 5)), "\"nul\\u0000x\"");
  // UTF-8 passes through unchanged.
  EXPECT_EQ(JsonQuote("\xc3\xa9t\xc3\xa9"), "\"\xc3\xa9t\xc3\xa9\"");
}

TEST(JsonWriter, CompactNestedDocument) {
  JsonWriter json(0);
  json.BeginObject()
      .Member("pairs", 785)
      .Member("alignment", "se3")
      .Member("ok", true)
      .Key("ate")
      .BeginObject()
      .Member("rmse", 0.5)
      .EndObject()
      .Key("list")
      .BeginArray()
      .Value(1)
      .Value(2.25)
      .Null()
      .EndArray()
      .Key("empty")
      .BeginObject()
      .EndObject()
      .EndObject();
  EXPECT_EQ(json.str(), R"({"pairs":785,"alignment":"se3","ok":true,"ate":{"rmse":0.5},)"
                        R"("list":[1,2.25,null],"empty":{}})");
}

TEST(JsonWriter, PrettyPrintsWithIndent) {
  JsonWriter json(2);
  json.BeginObject().Member("a", 1).Key("b").BeginArray().Value("x").EndArray().EndObject();
  EXPECT_EQ(json.str(), "{\n  \"a\": 1,\n  \"b\": [\n    \"x\"\n  ]\n}\n");
}

TEST(JsonWriter, DoublesRoundTripAndNonFiniteBecomesNull) {
  const double values[] = {0.1, 1.0 / 3.0, 0.008119123456789, 1e-300, -2.5e20, 0.0};
  for (const double v : values) {
    JsonWriter json(0);
    json.BeginArray().Value(v).EndArray();
    const std::string s = json.str();
    const std::string number = s.substr(1, s.size() - 2);
    EXPECT_EQ(std::strtod(number.c_str(), nullptr), v) << number;
  }
  JsonWriter json(0);
  json.BeginArray()
      .Value(std::numeric_limits<double>::quiet_NaN())
      .Value(std::numeric_limits<double>::infinity())
      .EndArray();
  EXPECT_EQ(json.str(), "[null,null]");
}

TEST(JsonWriter, Int64ExtremesAreExact) {
  JsonWriter json(0);
  json.BeginArray()
      .Value(std::numeric_limits<std::int64_t>::min())
      .Value(std::numeric_limits<std::uint64_t>::max())
      .EndArray();
  EXPECT_EQ(json.str(), "[-9223372036854775808,18446744073709551615]");
}

TEST(JsonWriter, MisuseThrows) {
  {
    JsonWriter json;
    json.BeginObject();
    EXPECT_THROW(json.Value(1), Error);  // value without a key
  }
  {
    JsonWriter json;
    EXPECT_THROW(json.Key("k"), Error);  // key outside an object
  }
  {
    JsonWriter json;
    json.BeginArray();
    EXPECT_THROW(json.EndObject(), Error);  // mismatched scope
    EXPECT_THROW(json.str(), Error);        // incomplete document
  }
  {
    JsonWriter json;
    json.BeginObject().Key("k");
    EXPECT_THROW(json.Key("k2"), Error);    // two keys in a row
    EXPECT_THROW(json.EndObject(), Error);  // key without a value
  }
  {
    JsonWriter json;
    json.Value(1);
    EXPECT_THROW(json.Value(2), Error);  // second top-level value
  }
}

}  // namespace
}  // namespace pkslam
