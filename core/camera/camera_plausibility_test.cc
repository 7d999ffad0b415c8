#include "core/camera/camera_plausibility.h"

#include <gtest/gtest.h>

namespace pkslam {
namespace {

// EuRoC V1_01 cam0 as calibrated.
CameraModel Euroc(double fx = 458.654, double cx = 367.215, double k1 = -0.28340811) {
  return CameraModel::Pinhole(752, 480, fx, 457.296, cx, 248.375,
                              {k1, 0.07395907, 0.00019359, 1.76187114e-05});
}

std::string Parameter(const CameraModel& c) {
  const auto bad = FindImplausibleParameter(c);
  return bad ? bad->parameter : "";
}

TEST(FindImplausibleParameter, RealCamerasPass) {
  EXPECT_EQ(Parameter(Euroc()), "");
  EXPECT_EQ(Parameter(CameraModel::Pinhole(640, 480, 525, 525, 319.5, 239.5)), "");  // TUM
  EXPECT_EQ(Parameter(CameraModel::Pinhole(1241, 376, 718.856, 718.856, 607.19, 185.22)),
            "");  // KITTI 00
  EXPECT_EQ(Parameter(CameraModel::KannalaBrandt8(512, 512, 190.98, 190.98, 254.93, 256.90,
                                                  {0.0035, 0.0007, -0.0011, 0.0002})),
            "");  // TUM-VI
}

TEST(FindImplausibleParameter, NamesTheParameterThatIsOff) {
  EXPECT_EQ(Parameter(Euroc(458.654, 3672.15)), "cx");   // a digit too many
  EXPECT_EQ(Parameter(Euroc(458.654, -3000)), "cx");
  EXPECT_EQ(Parameter(Euroc(45865.4)), "fx");
  EXPECT_EQ(Parameter(Euroc(4.58654)), "fx");
  EXPECT_EQ(Parameter(Euroc(200.0)), "fy");  // fy/fx = 2.3
  EXPECT_EQ(Parameter(Euroc(458.654, 367.215, 50.0)), "distortion");
  EXPECT_EQ(Parameter(Euroc(458.654, 367.215, -5.0)), "distortion");
  const auto bad = FindImplausibleParameter(Euroc(458.654, 3672.15));
  ASSERT_TRUE(bad);
  EXPECT_NE(bad->what.find("3672.15"), std::string::npos) << bad->what;
}

}  // namespace
}  // namespace pkslam
