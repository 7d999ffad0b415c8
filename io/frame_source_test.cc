// Frame sources: a video written with OpenCV's VideoWriter comes back frame for frame with
// increasing container timestamps (or --fps stamps); an image folder follows its timestamps
// file; bad inputs name the file (and line).
#include "io/frame_source.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

cv::Mat Pattern(int k) {
  cv::Mat image(120, 160, CV_8UC3, cv::Scalar(30, 30, 30));
  cv::rectangle(image, cv::Rect(10 + 5 * k, 20, 40, 40), cv::Scalar(200, 220, 240), cv::FILLED);
  return image;
}

TEST(FrameSource, VideoFileFramesAndTimestamps) {
  const auto dir = testing::MakeTempDir("frame_source_video");
  const auto file = dir / "clip.avi";
  {
    cv::VideoWriter writer(file.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 20.0,
                           cv::Size(160, 120));
    ASSERT_TRUE(writer.isOpened());
    for (int k = 0; k < 12; ++k) writer.write(Pattern(k));
  }
  auto source = OpenVideoFile(file);
  ASSERT_TRUE(source->Count().has_value());
  EXPECT_EQ(*source->Count(), 12u);
  int frames = 0;
  std::int64_t last = -1;
  while (auto f = source->Next()) {
    EXPECT_EQ(f->image.type(), CV_8UC1);
    EXPECT_EQ(f->image.cols, 160);
    EXPECT_GT(f->t_ns, last);
    last = f->t_ns;
    ++frames;
  }
  EXPECT_EQ(frames, 12);
  EXPECT_NEAR(static_cast<double>(last) * 1e-9, 11 / 20.0, 1e-3);  // 20 fps container
  auto fixed = OpenVideoFile(file, 10.0);
  fixed->Next();
  EXPECT_EQ(fixed->Next()->t_ns, 100'000'000);
  EXPECT_THROW(OpenVideoFile(dir / "missing.mp4"), InputError);
  std::ofstream(dir / "not_a_video.mp4") << "hello";
  EXPECT_THROW(OpenVideoFile(dir / "not_a_video.mp4"), InputError);
  EXPECT_THROW(OpenVideoFile(file, -1.0), OptionError);
}

TEST(FrameSource, ImageFolderFollowsItsTimestamps) {
  const auto dir = testing::MakeTempDir("frame_source_folder");
  for (int k = 0; k < 3; ++k) {
    cv::imwrite((dir / (std::to_string(1000 + k) + ".png")).string(), Pattern(k));
  }
  std::ofstream(dir / "times.txt") << "# t_ns\n1000\n1001\n1002\n";
  auto source = OpenImageFolder(dir, dir / "times.txt");
  EXPECT_EQ(*source->Count(), 3u);
  EXPECT_EQ(source->Next()->t_ns, 1000);
  EXPECT_EQ(source->Next()->t_ns, 1001);
  EXPECT_EQ(source->Next()->image.type(), CV_8UC1);
  EXPECT_FALSE(source->Next().has_value());
  // Seconds with names; a listed image that is missing names the timestamps file and line.
  std::ofstream(dir / "named.txt") << "0.5 1000.png\n1.0 missing\n";
  auto named = OpenImageFolder(dir, dir / "named.txt");
  EXPECT_EQ(named->Next()->t_ns, 500'000'000);
  try {
    named->Next();
    FAIL() << "missing image accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 2u);
  }
  std::ofstream(dir / "backwards.txt") << "1002\n1001\n";
  EXPECT_THROW(OpenImageFolder(dir, dir / "backwards.txt"), InputError);
  EXPECT_THROW(OpenImageFolder(dir / "nope", dir / "times.txt"), InputError);
}

}  // namespace
}  // namespace pkslam
