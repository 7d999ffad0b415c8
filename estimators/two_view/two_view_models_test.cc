// Building blocks of the two-view initialiser on exact synthetic geometry: model fitting,
// scoring, decompositions and triangulation.
#include "estimators/two_view/two_view_models.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "core/geometry/so3.h"
#include "estimators/two_view/two_view_motion.h"
#include "estimators/two_view/two_view_refine.h"

namespace pkslam::two_view {
namespace {

const Pinhole kCamera{435.0, 435.0, 367.0, 248.0};

Motion MakeMotion(const Eigen::Vector3d& rotation_vector, const Eigen::Vector3d& translation) {
  return Motion{SO3d::Exp(rotation_vector).Matrix(), translation};
}

double RotationAngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double c = std::clamp(((a * b.transpose()).trace() - 1) / 2, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

// Pixels of random points (planar when plane_normal is given: n^T X = plane_d).
Correspondences Project(const Motion& m, int n, std::uint64_t seed, double noise,
                        const Eigen::Vector3d* plane_normal = nullptr, double plane_d = 5.0,
                        std::vector<Eigen::Vector3d>* points = nullptr) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(-3, 3), uy(-2, 2), uz(3, 8);
  std::normal_distribution<double> gauss(0, noise);
  Correspondences c;
  while (c.size() < n) {
    Eigen::Vector3d p(ux(rng), uy(rng), uz(rng));
    if (plane_normal) {
      // Move the point along its viewing ray onto the plane.
      p *= plane_d / plane_normal->dot(p);
    }
    const Eigen::Vector3d p2 = m.rotation * p + m.translation;
    if (p.z() <= 0 || p2.z() <= 0) continue;
    c.first.push_back(kCamera.Project(p) + Eigen::Vector2d(gauss(rng), gauss(rng)));
    c.second.push_back(kCamera.Project(p2) + Eigen::Vector2d(gauss(rng), gauss(rng)));
    if (points) points->push_back(p);
  }
  return c;
}

TEST(TwoViewModels, NormalizationCentresAndScales) {
  const Correspondences c = Project(MakeMotion({0, 0.1, 0}, {0.5, 0, 0}), 100, 1, 0);
  const NormalizedPoints np = NormalizePoints(c.first);
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  double dist = 0;
  for (const auto& p : np.points) {
    mean += p;
    dist += p.norm();
  }
  EXPECT_LT((mean / 100).norm(), 1e-12);
  EXPECT_NEAR(dist / 100, std::sqrt(2.0), 1e-12);
  EXPECT_LT((np.transform * c.first[7].homogeneous()).hnormalized().x() - np.points[7].x(), 1e-12);
}

TEST(TwoViewModels, HomographyFromEightExactPlanarPairs) {
  const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -0.1, 1).normalized();
  const Motion m = MakeMotion({0.02, 0.1, -0.03}, {0.4, 0.1, 0.05});
  const Correspondences c = Project(m, 8, 2, 0, &normal);
  const NormalizedPoints n1 = NormalizePoints(c.first), n2 = NormalizePoints(c.second);
  const Eigen::Matrix3d h21 =
      n2.transform.inverse() * ComputeHomographyDlt(n1.points, n2.points) * n1.transform;
  // Ground truth: H = K (R + t n^T / d) K^-1 (up to scale).
  Eigen::Matrix3d truth =
      kCamera.K() * (m.rotation + m.translation * normal.transpose() / 5.0) * kCamera.K().inverse();
  truth /= truth(2, 2);
  EXPECT_LT((h21 / h21(2, 2) - truth).norm(), 1e-8 * truth.norm());
}

TEST(TwoViewModels, FundamentalHasRankTwoAndFitsExactPairs) {
  const Motion m = MakeMotion({0.01, -0.05, 0.02}, {0.5, 0.1, 0.1});
  const Correspondences c = Project(m, 50, 3, 0);
  const NormalizedPoints n1 = NormalizePoints(c.first), n2 = NormalizePoints(c.second);
  const std::vector<Eigen::Vector2d> s1(n1.points.begin(), n1.points.begin() + 8);
  const std::vector<Eigen::Vector2d> s2(n2.points.begin(), n2.points.begin() + 8);
  const Eigen::Matrix3d f21 =
      n2.transform.transpose() * ComputeFundamentalEightPoint(s1, s2) * n1.transform;
  EXPECT_LT(std::abs(f21.determinant()) / std::pow(f21.norm(), 3), 1e-12);
  // All 50 pairs (not only the fitted eight) lie on their epipolar lines.
  std::vector<std::uint8_t> inliers;
  const double score = ScoreFundamental(f21, c, 1.0, &inliers);
  EXPECT_NEAR(score, 2 * 50 * kChi2TwoDof, 1e-6);
  for (auto in : inliers) EXPECT_EQ(in, 1);
}

TEST(TwoViewModels, ScoresSeparateInliersFromOutliers) {
  const Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  const Motion m = MakeMotion({0, 0.05, 0}, {0.3, 0, 0});
  Correspondences c = Project(m, 40, 4, 0, &normal);
  const Eigen::Matrix3d h21 =
      kCamera.K() * (m.rotation + m.translation * normal.transpose() / 5.0) * kCamera.K().inverse();
  // Every fourth second-image point moved by 10 px breaks the homography transfer.
  for (int i = 0; i < c.size(); i += 4) c.second[i] += Eigen::Vector2d(6, 8);
  // Another one 1.5 px off: still an inlier, scoring less than the exact ones.
  c.second[1] += Eigen::Vector2d(1.5, 0);
  std::vector<std::uint8_t> inliers;
  const double score = ScoreHomography(h21, h21.inverse(), c, 1.0, &inliers);
  int count = 0;
  for (int i = 0; i < c.size(); ++i) {
    EXPECT_EQ(inliers[i], i % 4 == 0 ? 0 : 1) << i;
    count += inliers[i];
  }
  EXPECT_EQ(count, 30);
  EXPECT_LT(score, 2 * 30 * kChi2TwoDof);
  EXPECT_GT(score, 2 * 29 * kChi2TwoDof);
}

TEST(TwoViewModels, RansacFindsTheModelDespiteOutliers) {
  const Motion m = MakeMotion({0.01, -0.05, 0.02}, {0.5, 0.1, 0.1});
  Correspondences c = Project(m, 300, 5, 0.5);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 700);
  for (int i = 0; i < c.size(); i += 3) c.second[i] = Eigen::Vector2d(u(rng), u(rng) * 0.65);
  std::vector<MinimalSet> sets;
  std::uniform_int_distribution<int> pick(0, c.size() - 1);
  for (int k = 0; k < 200; ++k) {
    MinimalSet s;
    for (int j = 0; j < kMinimalSetSize; ++j) {
      bool dup;
      do {
        s[j] = pick(rng);
        dup = false;
        for (int q = 0; q < j; ++q) dup |= s[q] == s[j];
      } while (dup);
    }
    sets.push_back(s);
  }
  const ModelFit f = RansacFundamental(c, NormalizePoints(c.first), NormalizePoints(c.second), sets,
                                       RansacOptions{});
  // 2/3 of the pairs are true; a few random outliers land near their epipolar line.
  EXPECT_GE(f.num_inliers, 180);
  EXPECT_LE(f.num_inliers, 215);
  int true_inliers = 0;
  for (int i = 0; i < c.size(); ++i) true_inliers += (i % 3 != 0) && f.inliers[i];
  EXPECT_GE(true_inliers, 180);
}

TEST(TwoViewMotion, EssentialDecompositionContainsTheTruth) {
  const Motion m = MakeMotion({0.05, -0.2, 0.1}, Eigen::Vector3d(0.3, -0.2, 0.9).normalized());
  const Eigen::Matrix3d t_hat = SO3d::Hat(m.translation);
  const std::vector<Motion> candidates = DecomposeEssential(-3.0 * t_hat * m.rotation);
  ASSERT_EQ(candidates.size(), 4u);
  int found = 0;
  for (const Motion& c : candidates) {
    EXPECT_NEAR(c.rotation.determinant(), 1.0, 1e-12);
    if (RotationAngleDeg(c.rotation, m.rotation) < 1e-6 &&
        (c.translation - m.translation).norm() < 1e-9) {
      ++found;
    }
  }
  EXPECT_EQ(found, 1);
}

TEST(TwoViewMotion, HomographyDecompositionContainsTheTruth) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const Motion m = MakeMotion(0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng)),
                                Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized());
    const Eigen::Vector3d normal = Eigen::Vector3d(u(rng), u(rng), 2 + u(rng)).normalized();
    const double d = 3 + u(rng);
    // Arbitrary scale and sign, as a homography comes out of the DLT.
    const double scale = trial % 2 ? -0.7 : 2.5;
    const Eigen::Matrix3d a21 = scale * (m.rotation + m.translation * normal.transpose() / d);
    const std::vector<PlanarMotion> candidates = DecomposeHomography(a21);
    ASSERT_EQ(candidates.size(), 8u);
    int found = 0;
    for (const PlanarMotion& c : candidates) {
      EXPECT_NEAR(c.motion.rotation.determinant(), 1.0, 1e-9);
      EXPECT_LT(
          (c.motion.rotation.transpose() * c.motion.rotation - Eigen::Matrix3d::Identity()).norm(),
          1e-9);
      // Every candidate explains the homography: a21 ~ R + t n^T / d' for some d'.
      if (RotationAngleDeg(c.motion.rotation, m.rotation) < 1e-5 &&
          (c.motion.translation - m.translation).norm() < 1e-6 &&
          (c.normal - normal).norm() < 1e-6) {
        ++found;
      }
    }
    EXPECT_GE(found, 1) << "trial " << trial;
  }
}

TEST(TwoViewMotion, HomographyOfPureRotationIsDegenerate) {
  const Motion m = MakeMotion({0.05, 0.1, 0}, Eigen::Vector3d::Zero());
  EXPECT_TRUE(DecomposeHomography(1.3 * m.rotation).empty());
}

TEST(TwoViewMotion, TriangulationRecoversExactPoints) {
  const Motion m = MakeMotion({0.0, 0.05, 0.01}, {-0.4, 0.05, 0.02});
  std::vector<Eigen::Vector3d> points;
  const Correspondences c = Project(m, 30, 6, 0, nullptr, 5.0, &points);
  for (int i = 0; i < c.size(); ++i) {
    const Eigen::Vector3d p =
        TriangulateLinear(kCamera.Normalize(c.first[i]), kCamera.Normalize(c.second[i]), m);
    EXPECT_LT((p - points[i]).norm(), 1e-9 * points[i].norm());
  }
}

TEST(TwoViewMotion, CheckMotionAcceptsTruthAndRejectsMirroredHypotheses) {
  const Motion m = MakeMotion({0.0, 0.05, 0.01}, Eigen::Vector3d(-1, 0.1, 0.05).normalized());
  const Correspondences pixels = Project(m, 200, 7, 0.3);
  Correspondences normalized;
  for (int i = 0; i < pixels.size(); ++i) {
    normalized.first.push_back(kCamera.Normalize(pixels.first[i]));
    normalized.second.push_back(kCamera.Normalize(pixels.second[i]));
  }
  std::vector<std::uint8_t> inliers(pixels.size(), 1);
  inliers[0] = 0;  // masked correspondences are skipped
  const MotionCheck truth = CheckMotion(m, pixels, normalized, inliers, kCamera, kCamera, 4.0);
  EXPECT_EQ(truth.num_good, 199);
  EXPECT_EQ(truth.triangulated[0], 0);
  // Unit baseline at 3-8 m: the 51st largest of 199 angles lies within the possible range.
  EXPECT_GT(truth.parallax_deg, 6.0);
  EXPECT_LT(truth.parallax_deg, 20.0);
  const Motion mirrored{m.rotation, -m.translation};
  const MotionCheck bad = CheckMotion(mirrored, pixels, normalized, inliers, kCamera, kCamera, 4.0);
  EXPECT_EQ(bad.num_good, 0);
  EXPECT_EQ(bad.parallax_deg, 0.0);
}

Correspondences ToNormalized(const Correspondences& pixels) {
  Correspondences normalized;
  for (int i = 0; i < pixels.size(); ++i) {
    normalized.first.push_back(kCamera.Normalize(pixels.first[i]));
    normalized.second.push_back(kCamera.Normalize(pixels.second[i]));
  }
  return normalized;
}

TEST(TwoViewRefine, ConvergesToTheExactMotionFromAPerturbedStart) {
  const Motion truth = MakeMotion({0.02, -0.06, 0.01}, Eigen::Vector3d(0.9, 0.1, 0.2).normalized());
  const Correspondences normalized = ToNormalized(Project(truth, 300, 12, 0));
  std::vector<std::uint8_t> mask(normalized.size(), 1);
  // 3 degrees off in rotation, ~6 in translation direction.
  const Motion start{SO3d::Exp(Eigen::Vector3d(0.03, -0.03, 0.02)).Matrix() * truth.rotation,
                     (truth.translation + Eigen::Vector3d(0, 0.1, -0.05)).normalized()};
  const MotionRefinement r = RefineMotion(start, normalized, mask);
  EXPECT_GT(r.initial_rms, 1e-3);
  EXPECT_LT(r.final_rms, 1e-9);
  EXPECT_LT(RotationAngleDeg(r.motion.rotation, truth.rotation), 1e-5);
  EXPECT_LT((r.motion.translation - truth.translation).norm(), 1e-7);
  EXPECT_NEAR(r.motion.translation.norm(), 1.0, 1e-12);
}

TEST(TwoViewRefine, SampsonGateSeparatesOffEpipolarMatches) {
  const Motion truth = MakeMotion({0.0, 0.04, 0.0}, Eigen::Vector3d(1, 0, 0.1).normalized());
  Correspondences pixels = Project(truth, 50, 13, 0);
  // Move every fifth second-image point 8 px across its (nearly horizontal) epipolar line.
  for (int i = 0; i < pixels.size(); i += 5) pixels.second[i].y() += 8;
  const std::vector<std::uint8_t> mask =
      SampsonInliers(truth, ToNormalized(pixels), 2.0 / kCamera.fx);
  for (int i = 0; i < pixels.size(); ++i) EXPECT_EQ(mask[i], i % 5 == 0 ? 0 : 1) << i;
}

}  // namespace
}  // namespace pkslam::two_view
