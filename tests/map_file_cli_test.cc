// End-to-end: map files from the command line (issue 23). A stereo run saves its map; `pkslam
// map roundtrip` reloads and re-saves it byte for byte; a localise-only run on the same
// frames relocalises into it and tracks without adding keyframes; damaged files and missing
// options give one-line errors and a non-zero exit.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using ::testing::HasSubstr;

using testing::RunPkslam;

using testing::JsonIntField;

TEST(MapFileCli, SaveRoundTripLocaliseAndRefuseDamage) {
  const auto dir = testing::MakeTempDir("map_file_cli");
  const auto seq = dir / "seq";
  const auto sim = RunPkslam(fmt::format(
      "--log-level warn simulate --out '{}' --motion medium --duration 4 --quality fast --quiet "
      "--no-cloud --seed 2",
      seq.string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;

  const auto map = dir / "map.pkmap";
  const auto mapping = RunPkslam(fmt::format(
      "run --dataset '{}' --sensor stereo --deterministic --quiet --save-map '{}' --out '{}'",
      seq.string(), map.string(), (dir / "mapping").string()));
  ASSERT_EQ(mapping.exit_code, 0) << mapping.output;
  ASSERT_TRUE(std::filesystem::exists(map));
  const long long keyframes = JsonIntField(dir / "mapping/stats.json", "keyframes");
  ASSERT_GT(keyframes, 2);

  const auto info = RunPkslam(fmt::format("map info '{}'", map.string()));
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_THAT(info.output, HasSubstr(fmt::format("{} keyframes", keyframes)));

  const auto roundtrip = RunPkslam(
      fmt::format("map roundtrip '{}' --dataset '{}' --sensor stereo", map.string(), seq.string()));
  ASSERT_EQ(roundtrip.exit_code, 0) << roundtrip.output;
  EXPECT_THAT(roundtrip.output, HasSubstr("byte-identical"));

  const auto localise = RunPkslam(
      fmt::format("run --dataset '{}' --sensor stereo --deterministic --quiet --load-map '{}' "
                  "--localise-only --out '{}'",
                  seq.string(), map.string(), (dir / "localise").string()));
  ASSERT_EQ(localise.exit_code, 0) << localise.output;
  const auto stats = dir / "localise/stats.json";
  const long long frames = JsonIntField(stats, "frames");
  EXPECT_GE(JsonIntField(stats, "frames_in_trajectory"), frames * 9 / 10);
  EXPECT_EQ(JsonIntField(stats, "keyframes"), keyframes);  // no keyframe added

  // Damage: truncated, one bit flipped; and --localise-only without a map.
  std::string bytes = testing::ReadFileBytes(map);
  std::ofstream(dir / "truncated.pkmap", std::ios::binary) << bytes.substr(0, bytes.size() / 3);
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x04);
  std::ofstream(dir / "flipped.pkmap", std::ios::binary) << bytes;
  for (const auto& [name, reason] :
       {std::pair<std::string, std::string>{"truncated", "truncated"}, {"flipped", "checksum"}}) {
    const auto file = dir / (name + ".pkmap");
    const auto bad =
        RunPkslam(fmt::format("run --dataset '{}' --sensor stereo --quiet --load-map "
                              "'{}' --out '{}'",
                              seq.string(), file.string(), (dir / name).string()));
    EXPECT_EQ(bad.exit_code, 1) << bad.output;
    EXPECT_THAT(bad.output, HasSubstr(file.string()));
    EXPECT_THAT(bad.output, HasSubstr(reason));
  }
  const auto no_map =
      RunPkslam(fmt::format("run --dataset '{}' --sensor stereo --quiet --localise-only --out '{}'",
                            seq.string(), (dir / "no_map").string()));
  EXPECT_NE(no_map.exit_code, 0);
  EXPECT_THAT(no_map.output, HasSubstr("--localise-only needs --load-map"));
}

// Localisation beyond a short map: a 3 s map (2 s of it at rest), then the next 5 s of a
// difficult flight that mostly looks elsewhere. The run keeps a pose for nearly every frame —
// against the map where it is in view, by visual odometry where not — and says which.
TEST(MapFileCli, LocalisationGoesOnBeyondAShortMap) {
  const auto dir = testing::MakeTempDir("map_file_cli_short");
  const auto seq = dir / "seq";
  const auto sim = RunPkslam(fmt::format(
      "--log-level warn simulate --out '{}' --motion difficult --duration 8 --quality fast "
      "--quiet --no-cloud --seed 2",
      seq.string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const auto map = dir / "short.pkmap";
  const auto mapping = RunPkslam(fmt::format(
      "run --dataset '{}' --sensor stereo --deterministic --max-frames 60 --quiet --save-map "
      "'{}' --out '{}'",
      seq.string(), map.string(), (dir / "mapping").string()));
  ASSERT_EQ(mapping.exit_code, 0) << mapping.output;
  const auto localise = RunPkslam(fmt::format(
      "run --dataset '{}' --sensor stereo --deterministic --first-frame 60 --load-map '{}' "
      "--localise-only --out '{}'",
      seq.string(), map.string(), (dir / "localise").string()));
  ASSERT_EQ(localise.exit_code, 0) << localise.output;
  EXPECT_THAT(localise.output, ::testing::Not(HasSubstr("new (or reset) map")));
  const auto stats = dir / "localise/stats.json";
  const long long frames = JsonIntField(stats, "frames");
  EXPECT_GE(JsonIntField(stats, "frames_in_trajectory"), frames * 9 / 10);
  EXPECT_GT(JsonIntField(stats, "visual_odometry"), 0);
  EXPECT_GT(JsonIntField(stats, "localised"), JsonIntField(stats, "visual_odometry"));
  EXPECT_THAT(testing::ReadFileBytes(stats), HasSubstr("\"suspect\": false"));
  const auto eval = RunPkslam(fmt::format(
      "eval --gt '{}' --est '{}'", (seq / "mav0/state_groundtruth_estimate0/data.csv").string(),
      (dir / "localise/trajectory_body.txt").string()));
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
}

}  // namespace
}  // namespace pkslam
