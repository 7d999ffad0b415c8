// End-to-end tests of `pkslam vocab train|convert|info` through the built binary: training is
// reproducible for a seed, conversions round-trip byte for byte, bad input gives one error line.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

std::string ReadFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// A grey PGM of random 6x6-pixel blocks (plenty of FAST corners), written without OpenCV.
void WriteBlockImage(const fs::path& file, int seed) {
  constexpr int kWidth = 320, kHeight = 240, kBlock = 6;
  std::mt19937 rng(static_cast<unsigned>(seed));
  std::vector<unsigned char> blocks((kWidth / kBlock + 1) * (kHeight / kBlock + 1));
  for (auto& b : blocks) b = static_cast<unsigned char>(rng() % 256);
  std::ofstream out(file, std::ios::binary);
  out << "P5\n" << kWidth << ' ' << kHeight << "\n255\n";
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x)
      out.put(static_cast<char>(blocks[(y / kBlock) * (kWidth / kBlock + 1) + x / kBlock]));
  }
}

testing::CommandResult Vocab(const std::string& arguments) {
  return testing::RunCommand(fmt::format("'{}' --log-level warn vocab {}",
                                         testing::PkslamExecutable().string(), arguments));
}

class VocabCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("vocab_cli_test");
    fs::create_directories(dir_ / "images/sub");
    for (int i = 0; i < 6; ++i) {
      WriteBlockImage(dir_ / (i < 3 ? "images" : "images/sub") / fmt::format("im{}.pgm", i), i);
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Train(const std::string& out, int seed) {
    return fmt::format(
        "train --images '{}' --k 5 --L 3 --features 300 --seed {} --quiet --out '{}'",
        (dir_ / "images").string(), seed, (dir_ / out).string());
  }

  std::string ExpectOneLineError(const std::string& arguments) {
    const testing::CommandResult r = Vocab(arguments);
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.rfind("pkslam: error: ", 0), 0u) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    return r.output;
  }

  fs::path dir_;
};

TEST_F(VocabCliTest, TrainIsReproducibleAndConversionsRoundTrip) {
  ASSERT_EQ(Vocab(Train("a.pkvoc", 3)).exit_code, 0);
  ASSERT_EQ(Vocab(Train("b.pkvoc", 3)).exit_code, 0);
  ASSERT_EQ(Vocab(Train("c.pkvoc", 4)).exit_code, 0);
  const std::string a = ReadFile(dir_ / "a.pkvoc");
  EXPECT_GT(a.size(), 1000u);
  EXPECT_EQ(a, ReadFile(dir_ / "b.pkvoc"));
  EXPECT_NE(a, ReadFile(dir_ / "c.pkvoc"));

  const auto convert = [&](const char* in, const char* out) {
    return Vocab(fmt::format("convert '{}' '{}'", (dir_ / in).string(), (dir_ / out).string()))
        .exit_code;
  };
  ASSERT_EQ(convert("a.pkvoc", "a.txt"), 0);
  ASSERT_EQ(convert("a.txt", "a2.bin"), 0);
  ASSERT_EQ(convert("a2.bin", "a2.txt"), 0);
  EXPECT_EQ(ReadFile(dir_ / "a2.bin"), a);
  EXPECT_EQ(ReadFile(dir_ / "a2.txt"), ReadFile(dir_ / "a.txt"));
  EXPECT_EQ(ReadFile(dir_ / "a.txt").rfind("5 3  0 0\n", 0), 0u);

  const testing::CommandResult info = Vocab(fmt::format("info '{}'", (dir_ / "a.txt").string()));
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("format      DBoW2 text"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("k           5"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("L           3"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("weighting   tf-idf"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("words       "), std::string::npos) << info.output;
}

TEST_F(VocabCliTest, BadInputGivesOneErrorLine) {
  std::ofstream(dir_ / "bad.txt") << "10 6  0 0\n0 0 1 2 3\n";
  EXPECT_NE(
      ExpectOneLineError(fmt::format("info '{}'", (dir_ / "bad.txt").string())).find("bad.txt:2:"),
      std::string::npos);
  std::ofstream(dir_ / "bad.bin") << "PKVOCAB\n\x01";
  EXPECT_NE(
      ExpectOneLineError(fmt::format("info '{}'", (dir_ / "bad.bin").string())).find("offset"),
      std::string::npos);
  EXPECT_NE(ExpectOneLineError(Train("voc.yaml", 1)).find("extension"), std::string::npos);
  fs::create_directories(dir_ / "empty");
  EXPECT_NE(ExpectOneLineError(fmt::format("train --quiet --images '{}' --out '{}'",
                                           (dir_ / "empty").string(), (dir_ / "v.bin").string()))
                .find("no image files"),
            std::string::npos);
  std::ofstream(dir_ / "images/broken.png") << "not a png";
  EXPECT_NE(ExpectOneLineError(Train("v.bin", 1)).find("broken.png: cannot read image"),
            std::string::npos);
}

}  // namespace
}  // namespace pkslam
