#include "io/sparse_model.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

// Two keyframes, three keypoints each; point 7 seen by both, point 9 only by keyframe 4.
SparseModel SmallModel() {
  SparseModel m;
  m.camera = {752, 480, 435.2, 435.2, 367.5, 252.2, 47.9};
  SparseKeyframe a;
  a.id = 2;
  a.t_ns = 1600000000050000000;
  a.camera_from_world =
      SE3d(Eigen::Quaterniond(0.9, 0.1, -0.2, 0.3).normalized(), Eigen::Vector3d(0.5, -1.25, 2.0));
  a.keypoints = {{10.5f, 20.25f, 0, 7}, {100.0f, 200.0f, 3, -1}, {33.0f, 44.0f, 1, -1}};
  SparseKeyframe b;
  b.id = 4;
  b.t_ns = 1600000000550000000;
  b.keypoints = {{11.5f, 21.25f, 2, -1}, {5.0f, 6.0f, 0, 9}, {12.0f, 13.0f, 0, 7}};
  m.keyframes = {a, b};
  m.points = {{7, Eigen::Vector3d(1.0, 2.0, 3.0), {{2, 0}, {4, 2}}},
              {9, Eigen::Vector3d(-1.5, 0.25, 4.125), {{4, 1}}}};
  return m;
}

class SparseModelTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::MakeTempDir("sparse_model_test"); }
  void TearDown() override { fs::remove_all(dir_); }

  std::string ReadText(const fs::path& f) {
    std::ifstream in(f);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path WriteText(const std::string& text) {
    const fs::path f = dir_ / "model.txt";
    std::ofstream(f) << text;
    return f;
  }
  // The message of the InputError reading `text` throws.
  std::string ErrorOf(const std::string& text) {
    try {
      ReadSparseModel(WriteText(text));
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }

  fs::path dir_;
};

TEST_F(SparseModelTest, RoundTripKeepsEverything) {
  const SparseModel m = SmallModel();
  m.CheckConsistency();
  WriteSparseModel(m, dir_ / "m.txt");
  const SparseModel r = ReadSparseModel(dir_ / "m.txt");
  EXPECT_EQ(r.camera.width, 752);
  EXPECT_DOUBLE_EQ(r.camera.bf, 47.9);
  ASSERT_EQ(r.keyframes.size(), 2u);
  EXPECT_EQ(r.keyframes[0].id, 2);
  EXPECT_EQ(r.keyframes[0].t_ns, 1600000000050000000);
  EXPECT_LT((r.keyframes[0].camera_from_world.Matrix() - m.keyframes[0].camera_from_world.Matrix())
                .norm(),
            1e-9);
  ASSERT_EQ(r.keyframes[1].keypoints.size(), 3u);
  EXPECT_FLOAT_EQ(r.keyframes[0].keypoints[0].v, 20.25f);
  EXPECT_EQ(r.keyframes[1].keypoints[2].point_id, 7);
  EXPECT_EQ(r.keyframes[1].keypoints[0].octave, 2);
  ASSERT_EQ(r.points.size(), 2u);
  EXPECT_EQ(r.points[1].position_world, Eigen::Vector3d(-1.5, 0.25, 4.125));
  EXPECT_EQ(r.points[0].observations, m.points[0].observations);
  // Writing what was read gives the same bytes.
  WriteSparseModel(r, dir_ / "again.txt");
  EXPECT_EQ(ReadText(dir_ / "m.txt"), ReadText(dir_ / "again.txt"));
}

TEST_F(SparseModelTest, EmptyModelRoundTrips) {
  SparseModel m;
  m.camera = {640, 480, 500, 500, 320, 240, 0};
  WriteSparseModel(m, dir_ / "e.txt");
  const SparseModel r = ReadSparseModel(dir_ / "e.txt");
  EXPECT_TRUE(r.keyframes.empty());
  EXPECT_TRUE(r.points.empty());
}

TEST_F(SparseModelTest, InconsistentModelsAreRejected) {
  SparseModel m = SmallModel();
  m.keyframes[1].keypoints[2].point_id = -1;  // point 7 still lists (4, 2)
  EXPECT_THROW(m.CheckConsistency(), Error);
  m = SmallModel();
  m.points[1].observations = {{5, 1}};  // unknown keyframe
  EXPECT_THROW(m.CheckConsistency(), Error);
}

TEST_F(SparseModelTest, MalformedFilesNameTheLine) {
  WriteSparseModel(SmallModel(), dir_ / "good.txt");
  const std::string good = ReadText(dir_ / "good.txt");
  // Truncated: drop the last line.
  const std::string truncated = good.substr(0, good.rfind("point 9"));
  EXPECT_NE(ErrorOf(truncated).find("truncated"), std::string::npos) << ErrorOf(truncated);
  // A keypoint line with a word instead of a number: line 7 (magic, comment, camera, comment,
  // keyframes, keyframe, then the first keypoint).
  std::string bad = good;
  bad.replace(bad.find("10.5000"), 7, "ten");
  EXPECT_NE(ErrorOf(bad).find("model.txt:7:"), std::string::npos) << ErrorOf(bad);
  // Cross reference broken in the file.
  std::string broken = good;
  broken.replace(broken.find("point 9 -1.5"), 7, "point 8");
  EXPECT_NE(ErrorOf(broken).find("inconsistent"), std::string::npos) << ErrorOf(broken);
  EXPECT_NE(ErrorOf("hello 1\n").find("model.txt:1:"), std::string::npos);
  EXPECT_THROW(ReadSparseModel(dir_ / "missing.txt"), InputError);
}

}  // namespace
}  // namespace pkslam
