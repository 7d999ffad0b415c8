#include "io/tum_rgbd_dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/util/error.h"
#include "io/test_fixtures.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Pair;

constexpr std::int64_t kMs = 1'000'000;

TEST(AssociateTimestamps, GreedyOneToOneBySmallestDifference) {
  const std::vector<std::int64_t> a = {0, 10 * kMs, 20 * kMs, 30 * kMs};
  const std::vector<std::int64_t> b = {1 * kMs, 12 * kMs, 19 * kMs, 50 * kMs};
  // a3's only candidates are taken or exactly 20 ms away (the bound is strict).
  EXPECT_THAT(AssociateTimestamps(a, b, 20 * kMs), ElementsAre(Pair(0, 0), Pair(1, 1), Pair(2, 2)));
  // The closer a wins b even though a0 comes first.
  EXPECT_THAT(AssociateTimestamps({0, 4 * kMs}, {3 * kMs}, 20 * kMs), ElementsAre(Pair(1, 0)));
  EXPECT_TRUE(AssociateTimestamps({0}, {30 * kMs}, 20 * kMs).empty());
  EXPECT_TRUE(AssociateTimestamps({}, {0}, 20 * kMs).empty());
}

class TumSynthetic : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::MakeTempDir("tum");
    std::string rgb =
        "# color images\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n# timestamp filename\n";
    std::string depth = "# depth maps\n# file: 'x.bag'\n# timestamp filename\n";
    for (int i = 0; i < 4; ++i) {
      const std::string t_rgb = fmt::format("1305031102.{:06d}", 175304 + 33333 * i);
      const std::string t_depth = fmt::format("1305031102.{:06d}", 160407 + 33333 * i);
      rgb += fmt::format("{} rgb/{}.png\n", t_rgb, t_rgb);
      depth += fmt::format("{} depth/{}.png\n", t_depth, t_depth);
      testing::WriteTestImage(root_ / "rgb" / (t_rgb + ".png"), 30 + i, CV_8UC3);
      cv::Mat d(48, 64, CV_16UC1, cv::Scalar(5000 + 1000 * i));
      d.at<uint16_t>(0, 0) = 0;
      fs::create_directories(root_ / "depth");
      cv::imwrite((root_ / "depth" / (t_depth + ".png")).string(), d);
    }
    testing::WriteText(root_ / "rgb.txt", rgb);
    testing::WriteText(root_ / "depth.txt", depth);
    testing::WriteText(root_ / "groundtruth.txt",
                       "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n"
                       "1305031098.6659 1.3563 0.6305 1.6380 0.6132 0.5962 -0.3311 -0.3986\n"
                       "1305031098.6758 1.3543 0.6306 1.6360 0.6129 0.5966 -0.3316 -0.3980\n");
    testing::WriteText(root_ / "accelerometer.txt", "# ignored\n1305031098.6 0 0 9.8\n");
  }
  void TearDown() override { fs::remove_all(root_); }

  std::string OpenError() const {
    try {
      TumRgbdDataset::Open(root_);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no InputError";
    return "";
  }

  fs::path root_;
};

TEST_F(TumSynthetic, ReadsListsAssociatesAndLoads) {
  ASSERT_TRUE(TumRgbdDataset::LooksLikeTumRgbd(root_));
  const TumRgbdDataset d = TumRgbdDataset::Open(root_);
  ASSERT_EQ(d.rgb().images.size(), 4u);
  EXPECT_EQ(d.rgb().images[0].t_ns, 1'305'031'102'175'304'000);
  EXPECT_EQ(d.depth().images[1].t_ns, 1'305'031'102'193'740'000);
  ASSERT_EQ(d.associations().size(), 4u);  // 14.9 ms apart < 20 ms
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(d.associations()[i].rgb, i);
    EXPECT_EQ(d.associations()[i].depth, i);
  }
  ASSERT_EQ(d.ground_truth().size(), 2u);
  EXPECT_EQ(d.ground_truth()[1].t_ns, 1'305'031'098'675'800'000);
  EXPECT_NEAR(d.ground_truth()[0].world_from_camera.translation().z(), 1.6380, 1e-12);
  EXPECT_DOUBLE_EQ(d.depth_factor(), 5000);

  EXPECT_EQ(d.LoadRgbColour(1).type(), CV_8UC3);
  EXPECT_EQ(d.LoadRgbGrey(1).type(), CV_8UC1);
  const cv::Mat raw = d.LoadDepthRaw(2);
  EXPECT_EQ(raw.type(), CV_16UC1);
  EXPECT_EQ(raw.at<uint16_t>(5, 5), 7000);
  const cv::Mat metres = d.LoadDepthMetres(2);
  EXPECT_FLOAT_EQ(metres.at<float>(5, 5), 1.4f);
  EXPECT_FLOAT_EQ(metres.at<float>(0, 0), 0.0f);

  TumRgbdOptions tight;
  tight.max_difference_s = 0.01;
  EXPECT_TRUE(TumRgbdDataset::Open(root_, tight).associations().empty());
}

TEST_F(TumSynthetic, DepthFactorFromSettingsOrOptions) {
  testing::WriteText(root_ / "settings.yaml", "%YAML:1.0\nRGBD.DepthMapFactor: 1000.0\n");
  const TumRgbdDataset d = TumRgbdDataset::Open(root_);
  EXPECT_DOUBLE_EQ(d.depth_factor(), 1000);
  EXPECT_FLOAT_EQ(d.LoadDepthMetres(0).at<float>(1, 1), 5.0f);
  TumRgbdOptions options;
  options.depth_factor = 2500;
  EXPECT_DOUBLE_EQ(TumRgbdDataset::Open(root_, options).depth_factor(), 2500);
}

TEST_F(TumSynthetic, MissingFilesSkippedAndWrongDepthTypeRejected) {
  fs::remove(TumRgbdDataset::Open(root_).depth().images[0].path);
  const TumRgbdDataset d = TumRgbdDataset::Open(root_);
  EXPECT_EQ(d.depth().listed, 4u);
  EXPECT_EQ(d.depth().missing.size(), 1u);
  EXPECT_EQ(d.associations().size(), 3u);
  // An 8-bit image where depth is expected is an input error naming the file.
  testing::WriteTestImage(d.depth().images[0].path, 3);
  try {
    d.LoadDepthRaw(0);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), d.depth().images[0].path);
    EXPECT_THAT(e.what(), HasSubstr("16-bit"));
  }
}

TEST_F(TumSynthetic, BadListsAreInputErrors) {
  testing::WriteText(root_ / "rgb.txt", "# x\n1305031102.2 rgb/a.png\n1305031102.1 rgb/b.png\n");
  EXPECT_THAT(OpenError(), HasSubstr("rgb.txt:3: timestamp 1305031102100000000 is before"));
  testing::WriteText(root_ / "rgb.txt", "1305031102.2 rgb/a.png\n1305031102,3 rgb/b.png\n");
  EXPECT_THAT(OpenError(), HasSubstr("rgb.txt:2: expected 2 fields"));
  testing::WriteText(root_ / "rgb.txt", "1305031102.2e0 rgb/a.png\n");
  EXPECT_THAT(OpenError(), HasSubstr("rgb.txt:1: timestamp: '1305031102.2e0' is not a decimal"));
  testing::WriteText(root_ / "rgb.txt", "# only comments\n");
  EXPECT_THAT(OpenError(), HasSubstr("rgb.txt: no data rows"));
  testing::WriteText(root_ / "rgb.txt", "1305031102.2 rgb/a.png\n");
  testing::WriteText(root_ / "groundtruth.txt", "1305031098.6659 1.3 0.6 1.6 0.6 0.5 -0.3\n");
  EXPECT_THAT(OpenError(), HasSubstr("groundtruth.txt:1: expected 8 fields"));
  testing::WriteText(root_ / "groundtruth.txt", "1305031098.6659 1.3 0.6 1.6 0.6 0.5 -0.3 0.9\n");
  EXPECT_THAT(OpenError(), HasSubstr("groundtruth.txt:1: quaternion norm"));
}

}  // namespace
}  // namespace pkslam
