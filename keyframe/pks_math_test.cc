// PKS equations on hand-worked numbers (../shared/docs/PKS.md; paper Eq. 1-12).
#include "keyframe/pks_math.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pkslam::pks {
namespace {

// Eq. 2: Th_initial = (M_c D_r / M_r + A_c D_r / A_r) / 2
// Eq. 4: theta = 1 - M_c / M_r
// Eq. 6: beta = D_c / M_c - D_r / M_r
// Eq. 8: alpha = D_c / M_c - 0.5
// Eq. 9: Th_adaptive = Th_initial (1 + theta - beta - alpha)
TEST(PksAdaptiveThreshold, PaperEquationsByHand) {
  // A_c 400, M_c 200, D_c 60; A_r 500, M_r 300, D_r 30.
  const auto t = ComputeAdaptiveThreshold(400, 200, 60, 500, 300, 30, false);
  ASSERT_TRUE(t.valid);
  EXPECT_DOUBLE_EQ(t.th_initial, 22.0);  // (20 + 24) / 2
  EXPECT_NEAR(t.theta, 1.0 / 3.0, 1e-15);
  EXPECT_NEAR(t.beta, 0.2, 1e-15);    // 0.3 - 0.1
  EXPECT_NEAR(t.alpha, -0.2, 1e-15);  // 0.3 - 0.5
  EXPECT_DOUBLE_EQ(t.gamma, 0.0);
  EXPECT_NEAR(t.th_adaptive, 22.0 * 4.0 / 3.0, 1e-12);  // 29.333: D_c = 60 passes
}

TEST(PksAdaptiveThreshold, ReleasedGammaWhenMatchesHalve) {
  // M_c = 100 < M_r / 2: gamma = (300 - 200) / (300 + 200) = 0.2 is subtracted too.
  const auto paper = ComputeAdaptiveThreshold(400, 100, 60, 500, 300, 30, false);
  const auto released = ComputeAdaptiveThreshold(400, 100, 60, 500, 300, 30, true);
  EXPECT_DOUBLE_EQ(paper.th_initial, 17.0);                                   // (10 + 24) / 2
  EXPECT_NEAR(paper.th_adaptive, 17.0 * (1 + 2.0 / 3.0 - 0.5 - 0.1), 1e-12);  // 18.133
  EXPECT_NEAR(released.gamma, 0.2, 1e-15);
  EXPECT_NEAR(released.th_adaptive, 17.0 * (1 + 2.0 / 3.0 - 0.5 - 0.1 - 0.2), 1e-12);  // 14.733
  // D_c = 16 passes the released threshold but not the paper's.
  EXPECT_GT(16, released.th_adaptive);
  EXPECT_LT(16, paper.th_adaptive);
}

TEST(PksAdaptiveThreshold, ReleasedThetaClampChangesTheDecision) {
  // M_c 290 of M_r 300: theta = 1/30 < 0.1, so the released code uses 1.1 * Th_initial.
  const auto paper = ComputeAdaptiveThreshold(400, 290, 30, 500, 300, 30, false);
  const auto released = ComputeAdaptiveThreshold(400, 290, 30, 500, 300, 30, true);
  EXPECT_DOUBLE_EQ(paper.th_initial, 26.5);              // (29 + 24) / 2
  EXPECT_NEAR(released.th_adaptive, 1.1 * 26.5, 1e-12);  // 29.15
  const double beta = 30.0 / 290 - 0.1;
  const double alpha = 30.0 / 290 - 0.5;
  EXPECT_NEAR(paper.th_adaptive, 26.5 * (1 + 1.0 / 30 - beta - alpha), 1e-12);  // 32.32
  EXPECT_GT(30, released.th_adaptive);
  EXPECT_LT(30, paper.th_adaptive);
}

TEST(PksAdaptiveThreshold, DegenerateCounts) {
  EXPECT_FALSE(ComputeAdaptiveThreshold(400, 200, 60, 500, 0, 0, false).valid);   // M_r = 0
  EXPECT_FALSE(ComputeAdaptiveThreshold(400, 200, 60, 0, 300, 30, false).valid);  // A_r = 0
  EXPECT_FALSE(ComputeAdaptiveThreshold(400, 0, 0, 500, 300, 30, false).valid);   // M_c = 0
  // D_r = 0: the threshold is 0, so any changed region passes.
  const auto t = ComputeAdaptiveThreshold(400, 200, 1, 500, 300, 0, false);
  EXPECT_TRUE(t.valid);
  EXPECT_DOUBLE_EQ(t.th_initial, 0.0);
  EXPECT_GT(1, t.th_adaptive);
}

// Eq. 10: ECOG = d max2 / (2 sqrt2 max1); Eq. 11: d between the two largest cells;
// Eq. 12: |COG| = sqrt(Xc^2 + Yc^2).
TEST(PksEcog, IdealOppositeCornersIsOne) {
  const auto e = ComputeEcog({10, 0, 0, 0, 0, 0, 0, 0, 10}, 3, false);
  ASSERT_TRUE(e.valid);
  EXPECT_NEAR(e.distance, 2 * std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(e.ecog, 1.0, 1e-15);
  EXPECT_NEAR(e.cog, 0.0, 1e-15);
}

TEST(PksEcog, OneSidedPointsFail) {
  const auto e = ComputeEcog({10, 8, 0, 0, 0, 0, 0, 0, 0}, 3, false);
  EXPECT_EQ(e.max1, 10);
  EXPECT_EQ(e.max2, 8);
  EXPECT_NEAR(e.distance, 1.0, 1e-15);
  EXPECT_NEAR(e.ecog, 8.0 / (2 * std::sqrt(2.0) * 10), 1e-15);  // 0.2828
  EXPECT_NEAR(e.xc, -10.0 / 18, 1e-15);
  EXPECT_NEAR(e.yc, -1.0, 1e-15);
  EXPECT_NEAR(e.cog, std::hypot(10.0 / 18, 1.0), 1e-15);  // 1.1440
  EXPECT_LT(e.ecog, e.cog);
}

TEST(PksEcog, SpreadPointsPass) {
  const auto e = ComputeEcog({6, 0, 0, 0, 2, 0, 0, 0, 5}, 3, false);
  EXPECT_NEAR(e.ecog, 5.0 / 6.0, 1e-15);
  EXPECT_NEAR(e.xc, -1.0 / 13, 1e-15);
  EXPECT_NEAR(e.yc, -1.0 / 13, 1e-15);
  EXPECT_GT(e.ecog, e.cog);
}

TEST(PksEcog, TiesGoToTheFirstCellInRowMajorOrder) {
  const auto e = ComputeEcog({5, 0, 5, 0, 0, 0, 5, 0, 0}, 3, false);
  // max1 = cell (0,0), max2 = cell (0,2): d = 2.
  EXPECT_NEAR(e.distance, 2.0, 1e-15);
  EXPECT_NEAR(e.ecog, 2.0 * 5 / (2 * std::sqrt(2.0) * 5), 1e-15);
}

TEST(PksEcog, ReleasedLateDenominator) {
  const auto e = ComputeEcog({10, 8, 0, 0, 0, 0, 0, 0, 0}, 3, true);
  EXPECT_NEAR(e.ecog, 8.0 / (std::sqrt(2.0) * 10), 1e-15);
}

TEST(PksEcog, DegenerateGrids) {
  EXPECT_FALSE(ComputeEcog({0, 0, 0, 0, 0, 0, 0, 0, 0}, 3, false).valid);  // empty grid
  const auto single = ComputeEcog({0, 0, 0, 0, 7, 0, 0, 0, 0}, 3, false);
  EXPECT_TRUE(single.valid);
  EXPECT_DOUBLE_EQ(single.ecog, 0.0);  // no second cell: not balanced
  EXPECT_DOUBLE_EQ(single.cog, 0.0);
  EXPECT_FALSE(single.ecog > single.cog);
}

TEST(PksEcog, LargerGridsUseTheirOwnMaximumDistance) {
  std::vector<int> g(16, 0);
  g[0] = 4;
  g[15] = 4;
  EXPECT_NEAR(ComputeEcog(g, 4, false).ecog, 1.0, 1e-15);
}

TEST(PksCone, RegionBoundaries) {
  EXPECT_EQ(ConeRegion(0.0, 10, 4), 0);
  EXPECT_EQ(ConeRegion(10.0, 10, 4), 0);  // (0, 10]
  EXPECT_EQ(ConeRegion(10.001, 10, 4), 1);
  EXPECT_EQ(ConeRegion(20.0, 10, 4), 1);
  EXPECT_EQ(ConeRegion(25.0, 10, 4), 2);
  EXPECT_EQ(ConeRegion(30.0, 10, 4), 2);
  EXPECT_EQ(ConeRegion(30.5, 10, 4), 3);  // > 30
  EXPECT_EQ(ConeRegion(120.0, 10, 4), 3);
}

TEST(PksCone, ViewAngles) {
  const Eigen::Vector3d n(0, 0, 1);
  const Eigen::Vector3d p(0, 0, 0);
  EXPECT_NEAR(ViewAngleDeg(n, p, {0, 0, 5}, false), 0.0, 1e-12);
  EXPECT_NEAR(ViewAngleDeg(n, p, {5, 0, 5}, false), 45.0, 1e-12);
  EXPECT_NEAR(ViewAngleDeg(n, p, {0, 0, -5}, false), 0.0, 1e-12);  // unoriented axis
  // Released: the normal is reflected to world z >= 0 first.
  EXPECT_NEAR(ViewAngleDeg({0, 0, -1}, p, {0, 0, 5}, true), 0.0, 1e-12);
  EXPECT_NEAR(ViewAngleDeg({0, 0, -1}, p, {0, 0, -5}, true), 180.0, 1e-12);
}

TEST(PksNormals, PlaneGivesItsNormalAndTooFewPointsGiveNone) {
  std::vector<Eigen::Vector3d> plane;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) plane.emplace_back(0.1 * i, 0.1 * j + 0.01 * i, 2.0);
  }
  for (const auto& n : EstimateNormals(plane)) EXPECT_NEAR(std::abs(n.z()), 1.0, 1e-12);
  // A tilted plane z = x.
  std::vector<Eigen::Vector3d> tilted;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) tilted.emplace_back(0.1 * i, 0.13 * j, 0.1 * i);
  }
  const Eigen::Vector3d expected = Eigen::Vector3d(1, 0, -1).normalized();
  for (const auto& n : EstimateNormals(tilted)) EXPECT_NEAR(std::abs(n.dot(expected)), 1.0, 1e-9);
  // Fewer than k + 1 = 6 points: no normal at all.
  const std::vector<Eigen::Vector3d> few(plane.begin(), plane.begin() + 5);
  for (const auto& n : EstimateNormals(few)) EXPECT_TRUE(n.isZero());
}

TEST(PksNormals, ReleasedRawSumCancelsOnSymmetricNeighbourhoods) {
  // Neighbours at +x, -x, +y, -y (and one far point): the pairwise cross products cancel in
  // the released formula; the sign-aligned sum gives the plane's normal.
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 0},   {0.1, 0, 0},  {-0.1, 0, 0},
                                            {0, 0.1, 0}, {0, -0.1, 0}, {0.3, 0.3, 0}};
  EXPECT_TRUE(EstimateNormals(pts, 4, false)[0].isZero());
  EXPECT_NEAR(std::abs(EstimateNormals(pts, 4, true)[0].z()), 1.0, 1e-12);
}

TEST(PksNormals, NeighbourTiesResolveByIndex) {
  // Six neighbours at equal distance around the query: the five lowest indices are used, so
  // dropping the last one does not change the normal.
  std::vector<Eigen::Vector3d> pts = {{0, 0, 0}};
  for (int k = 0; k < 6; ++k) {
    const double a = k * M_PI / 3;
    pts.emplace_back(std::cos(a), std::sin(a), 0.2 * (k % 2));
  }
  const auto with_all = EstimateNormals(pts)[0];
  EXPECT_FALSE(with_all.isZero());
  auto reordered = pts;
  reordered[6] += Eigen::Vector3d(0, 0, 10);  // move the 6th far away
  EXPECT_LT((EstimateNormals(reordered)[0] - with_all).norm(), 1e-12);
}

TEST(PksGrid, CellsSplitTheImageInThirds) {
  EXPECT_EQ(GridCell(0, 0, 752, 480, 3), 0);
  EXPECT_EQ(GridCell(751, 0, 752, 480, 3), 2);
  EXPECT_EQ(GridCell(376, 240, 752, 480, 3), 4);
  EXPECT_EQ(GridCell(0, 479, 752, 480, 3), 6);
  EXPECT_EQ(GridCell(-5, 900, 752, 480, 3), 6);  // clamped
}

TEST(PksGrid, ReleasedStrictBinningDropsBorders) {
  // 752 x 480 bounds: columns split at 250.67 and 501.33, rows at 160 and 320.
  EXPECT_EQ(StrictGridCell(136, 80, 0, 752, 0, 480, 3), 0);
  EXPECT_EQ(StrictGridCell(616, 400, 0, 752, 0, 480, 3), 8);
  EXPECT_EQ(StrictGridCell(300, 200, 0, 752, 0, 480, 3), 4);
  EXPECT_FALSE(StrictGridCell(300, 160, 0, 752, 0, 480, 3));  // on a row border
  EXPECT_FALSE(StrictGridCell(0, 200, 0, 752, 0, 480, 3));    // on the image edge
  EXPECT_FALSE(StrictGridCell(-3, 200, 0, 752, 0, 480, 3));   // outside (GridCell clamps)
  EXPECT_EQ(StrictGridCell(10, 200, 5, 755, 0, 480, 3), 3);   // bounds need not start at 0
}

TEST(PksViewChange, ViewAngleChangeNeverExceedsTheParallax) {
  // A fixed normal: the change of the angle to it between two cameras is at most the angle
  // between the two rays (why delta = 30 deg needs 30 deg of parallax).
  const Eigen::Vector3d point(0, 0, 4);
  const Eigen::Vector3d normal = Eigen::Vector3d(0.3, -0.2, -1).normalized();
  const Eigen::Vector3d a(0, 0, 0);
  for (const Eigen::Vector3d& b :
       {Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(2, 1, 0.5), Eigen::Vector3d(-3, 0.2, 1)}) {
    const double change =
        std::abs(ViewAngleDeg(normal, point, a, false) - ViewAngleDeg(normal, point, b, false));
    EXPECT_LE(change, ParallaxDeg(point, a, b) + 1e-9);
  }
  EXPECT_NEAR(ParallaxDeg(point, Eigen::Vector3d(-4, 0, 4), Eigen::Vector3d(0, 0, 0)), 90.0, 1e-9);
  ViewChangeDiagnostics d;
  d.Add(3.0, point, a, Eigen::Vector3d(4, 0, 4));
  std::map<std::string, double> trace;
  d.Fill(&trace);
  EXPECT_DOUBLE_EQ(trace.at("view_change_max"), 3.0);
  EXPECT_NEAR(trace.at("parallax_p90"), 90.0, 1e-9);
}

}  // namespace
}  // namespace pkslam::pks
