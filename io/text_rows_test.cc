#include "io/text_rows.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path WriteFile(const fs::path& dir, const std::string& name, const std::string& text) {
  fs::path p = dir / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

TEST(ParseDecimalSecondsToNs, ExactForTumStyleTimestamps) {
  EXPECT_EQ(ParseDecimalSecondsToNs("1305031102.175304"), 1305031102175304000);
  // A double cannot hold this value to the ns; the digit-wise parse does.
  EXPECT_EQ(ParseDecimalSecondsToNs("1403715273.262142976"), 1403715273262142976);
  EXPECT_EQ(ParseDecimalSecondsToNs("12"), 12'000'000'000);
  EXPECT_EQ(ParseDecimalSecondsToNs("12."), 12'000'000'000);
  EXPECT_EQ(ParseDecimalSecondsToNs(".5"), 500'000'000);
  EXPECT_EQ(ParseDecimalSecondsToNs("-0.25"), -250'000'000);
  EXPECT_EQ(ParseDecimalSecondsToNs("+1.000000001"), 1'000'000'001);
}

TEST(ParseDecimalSecondsToNs, RoundsBeyondNanoseconds) {
  EXPECT_EQ(ParseDecimalSecondsToNs("1.0000000014"), 1'000'000'001);
  EXPECT_EQ(ParseDecimalSecondsToNs("1.0000000015"), 1'000'000'002);
  EXPECT_EQ(ParseDecimalSecondsToNs("-1.0000000015"), -1'000'000'002);
  EXPECT_EQ(ParseDecimalSecondsToNs("0.9999999999"), 1'000'000'000);
}

TEST(ParseDecimalSecondsToNs, RejectsMalformed) {
  for (const char* bad :
       {"", ".", "-", "1e9", "1.2.3", "12a", " 1", "0x10", "1,5", "99999999999.0"}) {
    EXPECT_FALSE(ParseDecimalSecondsToNs(bad).has_value()) << bad;
  }
}

TEST(ParseNumbers, Int64AndDouble) {
  EXPECT_EQ(ParseInt64("1403715273262142976"), 1403715273262142976);
  EXPECT_EQ(ParseInt64("-7"), -7);
  EXPECT_FALSE(ParseInt64("1.5").has_value());
  EXPECT_FALSE(ParseInt64("99999999999999999999").has_value());
  EXPECT_FALSE(ParseInt64("").has_value());
  EXPECT_DOUBLE_EQ(*ParseDouble("9.0874956666666655"), 9.0874956666666655);
  EXPECT_DOUBLE_EQ(*ParseDouble("1.76187114e-05"), 1.76187114e-05);
  EXPECT_FALSE(ParseDouble("nan").has_value());
  EXPECT_FALSE(ParseDouble("inf").has_value());
  EXPECT_FALSE(ParseDouble("1.0x").has_value());
}

TEST(ForEachDataRow, SkipsCommentsAndBlankLinesAndKeepsLineNumbers) {
  const fs::path dir = testing::MakeTempDir("text_rows");
  const fs::path f = WriteFile(dir, "a.csv", "#header\r\n1, a.png\r\n\r\n  # note\n2,b.png\n");
  std::vector<std::size_t> lines;
  std::vector<std::string> names;
  const std::size_t rows = ForEachDataRow(f, FieldSeparator::kComma, [&](const TextRow& r) {
    lines.push_back(r.line);
    ASSERT_EQ(r.fields.size(), 2u);
    names.emplace_back(r.fields[1]);
  });
  EXPECT_EQ(rows, 2u);
  EXPECT_EQ(lines, (std::vector<std::size_t>{2, 5}));
  EXPECT_EQ(names, (std::vector<std::string>{"a.png", "b.png"}));
  fs::remove_all(dir);
}

TEST(ForEachDataRow, WhitespaceSeparatedFields) {
  const fs::path dir = testing::MakeTempDir("text_rows");
  const fs::path f = WriteFile(dir, "rgb.txt", "# rgb\n1.5 \t rgb/1.png\n");
  std::vector<std::string> fields;
  ForEachDataRow(f, FieldSeparator::kWhitespace, [&](const TextRow& r) {
    for (auto s : r.fields) fields.emplace_back(s);
  });
  EXPECT_EQ(fields, (std::vector<std::string>{"1.5", "rgb/1.png"}));
  fs::remove_all(dir);
}

TEST(ForEachDataRow, MissingFileIsInputError) {
  try {
    ForEachDataRow("/nonexistent/data.csv", FieldSeparator::kComma, [](const TextRow&) {});
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/data.csv"));
    EXPECT_THAT(e.what(), HasSubstr("not found"));
  }
}

TEST(FieldChecks, ErrorsNameFileAndLine) {
  try {
    Int64Field("12x", "f.csv", 7, "timestamp [ns]");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 7u);
    EXPECT_THAT(e.what(), HasSubstr("f.csv:7: timestamp [ns]: '12x' is not an integer"));
  }
  EXPECT_NO_THROW(RequireIncreasing(std::nullopt, 5, "f.csv", 2));
  EXPECT_NO_THROW(RequireIncreasing(4, 5, "f.csv", 2));
  EXPECT_THROW(RequireIncreasing(5, 5, "f.csv", 3), InputError);
  try {
    RequireIncreasing(6, 5, "f.csv", 3);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("f.csv:3:"));
    EXPECT_THAT(e.what(), HasSubstr("strictly increasing"));
  }
  TextRow row;
  row.line = 9;
  row.fields = {"1", "2", "3"};
  EXPECT_THROW(RequireFieldCount(row, 2, "f.csv", "t,name"), InputError);
  EXPECT_NO_THROW(RequireFieldCount(row, 3, "f.csv", "a,b,c"));
}

}  // namespace
}  // namespace pkslam
