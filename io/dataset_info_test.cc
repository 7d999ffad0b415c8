#include "io/dataset_info.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/util/error.h"
#include "io/test_fixtures.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

TEST(GroupThousands, Formats) {
  EXPECT_EQ(GroupThousands(0), "0");
  EXPECT_EQ(GroupThousands(999), "999");
  EXPECT_EQ(GroupThousands(29120), "29,120");
  EXPECT_EQ(GroupThousands(1234567), "1,234,567");
}

TEST(DatasetInfo, DetectsLayoutsAndRejectsUnknown) {
  const fs::path root = testing::MakeTempDir("info");
  EXPECT_THROW(DetectDatasetLayout(root / "missing"), InputError);
  try {
    DetectDatasetLayout(root);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown dataset layout"));
  }
  testing::WriteText(root / "tum" / "rgb.txt", "1.0 rgb/a.png\n");
  testing::WriteText(root / "tum" / "depth.txt", "1.0 depth/a.png\n");
  EXPECT_EQ(DetectDatasetLayout(root / "tum"), DatasetLayout::kTumRgbd);
  testing::EurocFixture().Write(root / "euroc");
  EXPECT_EQ(DetectDatasetLayout(root / "euroc"), DatasetLayout::kEuroc);
  EXPECT_EQ(DetectDatasetLayout(root / "euroc" / "mav0"), DatasetLayout::kEuroc);
  fs::remove_all(root);
}

TEST(DatasetInfo, EurocSyntheticWithMissingFileAndGaps) {
  const fs::path root = testing::MakeTempDir("info");
  testing::EurocFixture fixture;
  fixture.frames = 6;
  fixture.Write(root);
  fs::remove(root / "mav0" / "cam1" / "data" / fmt::format("{}.png", fixture.FrameT(2)));
  const DatasetInfo info = ComputeDatasetInfo(root);
  ASSERT_NE(info.Find("cam1"), nullptr);
  EXPECT_EQ(info.Find("cam1")->listed, 6u);
  EXPECT_EQ(info.Find("cam1")->count, 5u);
  ASSERT_EQ(info.Find("cam1")->missing_files.size(), 1u);
  EXPECT_EQ(info.Find("cam1")->missing_files[0],
            fmt::format("mav0/cam1/data/{}.png", fixture.FrameT(2)));
  EXPECT_EQ(info.Find("cam1")->gaps.size(), 1u);
  EXPECT_EQ(info.stereo_pairs, 5u);
  EXPECT_EQ(info.Find("imu0")->count, 51u);
  EXPECT_NEAR(info.Find("imu0")->measured_rate_hz, 200.0, 1e-9);
  EXPECT_NEAR(info.Find("cam0")->SpanS(), 0.25, 1e-12);
  EXPECT_FALSE(info.has_ground_truth);

  const std::string text = FormatDatasetInfo(info);
  EXPECT_THAT(text, HasSubstr("5 frames (6 listed, 1 missing)"));
  EXPECT_THAT(text, HasSubstr("stereo pairs 5"));
  EXPECT_THAT(text, HasSubstr("missing      1 file\n"));
  EXPECT_THAT(text, HasSubstr("gaps cam1    1 interval > 1.5 nominal periods"));
  std::string json = DatasetInfoToJson(info);
  std::erase_if(json, [](char c) { return c == ' ' || c == '\n'; });
  EXPECT_THAT(json, HasSubstr("\"stereo_pairs\":5,"));
  EXPECT_THAT(json, HasSubstr("\"name\":\"imu0\""));
  EXPECT_THAT(json, HasSubstr("\"listed\":6,\"count\":5,\"missing\":1,"));
  EXPECT_THAT(json, HasSubstr("\"ground_truth\":{\"present\":false,\"count\":0}"));
  fs::remove_all(root);
}

TEST(DatasetInfo, SharedSliceV101Static) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const DatasetInfo info = ComputeDatasetInfo(shared / "euroc" / "V1_01_easy_static");
  EXPECT_EQ(info.layout, DatasetLayout::kEuroc);
  EXPECT_EQ(info.stereo_pairs, 95u);
  EXPECT_EQ(info.Find("cam1")->missing_files.size(), 4u);
  EXPECT_EQ(info.Find("imu0")->count, 29'120u);
  EXPECT_EQ(info.Find("imu0")->nominal_rate_hz, 200);
  EXPECT_NEAR(info.Find("imu0")->measured_rate_hz, 200.0, 0.01);
  EXPECT_NEAR(info.Find("cam0")->measured_rate_hz, 20.0, 0.001);
  EXPECT_TRUE(info.Find("imu0")->gaps.empty());
}

}  // namespace
}  // namespace pkslam
