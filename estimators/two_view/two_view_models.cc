#include "estimators/two_view/two_view_models.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <numeric>
#include <random>

#include "core/util/error.h"

namespace pkslam::two_view {

namespace {

using Vector9 = Eigen::Matrix<double, 9, 1>;
using Matrix9 = Eigen::Matrix<double, 9, 9>;

Eigen::Matrix3d Reshape(const Vector9& v) {
  Eigen::Matrix3d m;
  m << v(0), v(1), v(2), v(3), v(4), v(5), v(6), v(7), v(8);
  return m;
}

// Eigenvector of the smallest eigenvalue of the (symmetric) normal matrix A^T A: the
// least-squares solution of A x = 0, |x| = 1. Fine on Hartley-normalised data.
Vector9 SmallestEigenvector(const Matrix9& ata) {
  Eigen::SelfAdjointEigenSolver<Matrix9> solver(ata);
  return solver.eigenvectors().col(0);
}

Eigen::Matrix3d EnforceRankTwo(const Eigen::Matrix3d& f) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d s = svd.singularValues();
  s(2) = 0;
  return svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
}

}  // namespace

NormalizedPoints NormalizePoints(const std::vector<Eigen::Vector2d>& points) {
  NormalizedPoints out;
  const std::size_t n = points.size();
  if (n == 0) return out;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(n);
  double mean_distance = 0;
  for (const auto& p : points) mean_distance += (p - mean).norm();
  mean_distance /= static_cast<double>(n);
  // All points identical: keep unit scale (every fit on them is degenerate anyway).
  const double scale = mean_distance > 0 ? std::sqrt(2.0) / mean_distance : 1.0;
  out.transform << scale, 0, -scale * mean.x(), 0, scale, -scale * mean.y(), 0, 0, 1;
  out.points.reserve(n);
  for (const auto& p : points) out.points.push_back(scale * (p - mean));
  return out;
}

Eigen::Matrix3d ComputeHomographyDlt(const std::vector<Eigen::Vector2d>& p1,
                                     const std::vector<Eigen::Vector2d>& p2) {
  PKSLAM_CHECK(p1.size() == p2.size() && p1.size() >= 4, "homography needs >= 4 pairs, got {}",
               p1.size());
  // Two rows of p2 x (H p1) = 0 per correspondence, unknowns h = rows of H; least squares
  // through the normal matrix (well conditioned on Hartley-normalised points).
  Matrix9 ata = Matrix9::Zero();
  Eigen::Matrix<double, 2, 9> rows;
  for (std::size_t i = 0; i < p1.size(); ++i) {
    const double x1 = p1[i].x(), y1 = p1[i].y(), x2 = p2[i].x(), y2 = p2[i].y();
    rows.row(0) << 0, 0, 0, -x1, -y1, -1, y2 * x1, y2 * y1, y2;
    rows.row(1) << x1, y1, 1, 0, 0, 0, -x2 * x1, -x2 * y1, -x2;
    ata.noalias() += rows.transpose() * rows;
  }
  return Reshape(SmallestEigenvector(ata));
}

Eigen::Matrix3d ComputeFundamentalEightPoint(const std::vector<Eigen::Vector2d>& p1,
                                             const std::vector<Eigen::Vector2d>& p2) {
  PKSLAM_CHECK(p1.size() == p2.size() && p1.size() >= 8,
               "fundamental matrix needs >= 8 pairs, got {}", p1.size());
  const int n = static_cast<int>(p1.size());
  // One row of p2^T F p1 = 0 per correspondence, unknowns f = rows of F.
  const auto row = [&](int i) {
    const double x1 = p1[i].x(), y1 = p1[i].y(), x2 = p2[i].x(), y2 = p2[i].y();
    return Vector9(x2 * x1, x2 * y1, x2, y2 * x1, y2 * y1, y2, x1, y1, 1);
  };
  Vector9 f;
  if (n == kMinimalSetSize) {
    // Exactly determined: the null vector is the direction orthogonal to the eight rows, the
    // last column of the orthogonal factor of A^T (cheaper than an SVD).
    Eigen::Matrix<double, 9, 8> at;
    for (int i = 0; i < n; ++i) at.col(i) = row(i);
    const Eigen::HouseholderQR<Eigen::Matrix<double, 9, 8>> qr(at);
    f = qr.householderQ() * Vector9::Unit(8);
  } else {
    Matrix9 ata = Matrix9::Zero();
    for (int i = 0; i < n; ++i) {
      const Vector9 r = row(i);
      ata.noalias() += r * r.transpose();
    }
    f = SmallestEigenvector(ata);
  }
  // A fundamental matrix has rank 2: drop the smallest singular value.
  return EnforceRankTwo(Reshape(f));
}

double ScoreHomography(const Eigen::Matrix3d& h21, const Eigen::Matrix3d& h12,
                       const Correspondences& c, double sigma, std::vector<std::uint8_t>* inliers) {
  // Scalar code: this loop runs iterations x matches times and dominates RANSAC.
  const int n = c.size();
  inliers->resize(n);
  const double inv_sigma2 = 1.0 / (sigma * sigma);
  const Eigen::Matrix3d& a = h21;
  const Eigen::Matrix3d& b = h12;
  double score = 0;
  for (int i = 0; i < n; ++i) {
    const double x1 = c.first[i].x(), y1 = c.first[i].y();
    const double x2 = c.second[i].x(), y2 = c.second[i].y();
    bool inlier = true;
    // Second -> first. A NaN chi2 (point mapped to infinity) fails the gate as well.
    const double w1 = 1.0 / (b(2, 0) * x2 + b(2, 1) * y2 + b(2, 2));
    const double dx1 = x1 - (b(0, 0) * x2 + b(0, 1) * y2 + b(0, 2)) * w1;
    const double dy1 = y1 - (b(1, 0) * x2 + b(1, 1) * y2 + b(1, 2)) * w1;
    const double chi1 = (dx1 * dx1 + dy1 * dy1) * inv_sigma2;
    if (chi1 <= kChi2TwoDof) {
      score += kChi2TwoDof - chi1;
    } else {
      inlier = false;
    }
    // First -> second.
    const double w2 = 1.0 / (a(2, 0) * x1 + a(2, 1) * y1 + a(2, 2));
    const double dx2 = x2 - (a(0, 0) * x1 + a(0, 1) * y1 + a(0, 2)) * w2;
    const double dy2 = y2 - (a(1, 0) * x1 + a(1, 1) * y1 + a(1, 2)) * w2;
    const double chi2 = (dx2 * dx2 + dy2 * dy2) * inv_sigma2;
    if (chi2 <= kChi2TwoDof) {
      score += kChi2TwoDof - chi2;
    } else {
      inlier = false;
    }
    (*inliers)[i] = inlier ? 1 : 0;
  }
  return score;
}

double ScoreFundamental(const Eigen::Matrix3d& f21, const Correspondences& c, double sigma,
                        std::vector<std::uint8_t>* inliers) {
  const int n = c.size();
  inliers->resize(n);
  const double inv_sigma2 = 1.0 / (sigma * sigma);
  const Eigen::Matrix3d& f = f21;
  double score = 0;
  for (int i = 0; i < n; ++i) {
    const double x1 = c.first[i].x(), y1 = c.first[i].y();
    const double x2 = c.second[i].x(), y2 = c.second[i].y();
    // Epipolar line of p1 in the second image (a2, b2, c2) and of p2 in the first (a1, b1);
    // both distances share the residual p2^T F p1.
    const double a2 = f(0, 0) * x1 + f(0, 1) * y1 + f(0, 2);
    const double b2 = f(1, 0) * x1 + f(1, 1) * y1 + f(1, 2);
    const double c2 = f(2, 0) * x1 + f(2, 1) * y1 + f(2, 2);
    const double a1 = f(0, 0) * x2 + f(1, 0) * y2 + f(2, 0);
    const double b1 = f(0, 1) * x2 + f(1, 1) * y2 + f(2, 1);
    const double r = a2 * x2 + b2 * y2 + c2;
    const double r2 = r * r * inv_sigma2;
    bool inlier = true;
    // Distance of p2 to the epipolar line of p1, then of p1 to that of p2.
    const double chi2 = r2 / (a2 * a2 + b2 * b2);
    if (chi2 <= kChi2OneDof) {
      score += kChi2TwoDof - chi2;
    } else {
      inlier = false;
    }
    const double chi1 = r2 / (a1 * a1 + b1 * b1);
    if (chi1 <= kChi2OneDof) {
      score += kChi2TwoDof - chi1;
    } else {
      inlier = false;
    }
    (*inliers)[i] = inlier ? 1 : 0;
  }
  return score;
}

namespace {

// The homography fitted to a minimal set explains all of its points (both transfer
// directions within the chi2 gate): the set is coplanar, or the views lack parallax.
bool SetFitsOneHomography(const Correspondences& c, const MinimalSet& set,
                          const std::vector<Eigen::Vector2d>& s1,
                          const std::vector<Eigen::Vector2d>& s2, const NormalizedPoints& n1,
                          const Eigen::Matrix3d& t2_inv, double sigma) {
  const Eigen::Matrix3d h21 = t2_inv * ComputeHomographyDlt(s1, s2) * n1.transform;
  const Eigen::Matrix3d h12 = h21.inverse();
  const double gate = kChi2TwoDof * sigma * sigma;
  for (int j = 0; j < kMinimalSetSize; ++j) {
    const Eigen::Vector2d& p1 = c.first[set[j]];
    const Eigen::Vector2d& p2 = c.second[set[j]];
    const double e2 = (p2 - (h21 * p1.homogeneous()).hnormalized()).squaredNorm();
    const double e1 = (p1 - (h12 * p2.homogeneous()).hnormalized()).squaredNorm();
    if (!(e1 <= gate && e2 <= gate)) return false;
  }
  return true;
}

// A model during RANSAC: in normalised coordinates (for re-fitting) and in pixels.
struct Candidate {
  Eigen::Matrix3d normalized = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d pixels = Eigen::Matrix3d::Zero();
  double score = 0;
  std::vector<std::uint8_t> inliers;
};

// Shared RANSAC loop with optional local optimisation.
//   fit(points 1, points 2) -> model in normalised coordinates (minimal set);
//   refit(model, inliers) -> model re-fitted on all inliers (normalised coordinates);
//   denormalize(model) -> pixel model;  score(pixel model, inliers) -> score;
//   skip(set, points 1, points 2) -> true to ignore a degenerate sample.
// Local optimisation runs whenever a minimal sample scores better than every earlier
// sample (not only better than the best refined model), so an early sample that refined into
// a wrong basin does not block later, better seeds.
template <typename Fit, typename Refit, typename Denormalize, typename Score, typename Skip>
ModelFit RunRansac(const NormalizedPoints& normalized1, const NormalizedPoints& normalized2,
                   const std::vector<MinimalSet>& sets, int refine_iterations, const Fit& fit,
                   const Refit& refit, const Denormalize& denormalize, const Score& score,
                   const Skip& skip) {
  const int n = static_cast<int>(normalized1.points.size());
  ModelFit out;
  Candidate best;
  best.inliers.assign(n, 0);
  bool have_best = false;
  bool have_sample = false;
  double best_sample_score = 0;
  std::vector<Eigen::Vector2d> s1(kMinimalSetSize), s2(kMinimalSetSize);
  Candidate current, trial;
  for (const MinimalSet& set : sets) {
    for (int j = 0; j < kMinimalSetSize; ++j) {
      s1[j] = normalized1.points[set[j]];
      s2[j] = normalized2.points[set[j]];
    }
    if (skip(set, s1, s2)) {
      ++out.degenerate_samples;
      continue;
    }
    current.normalized = fit(s1, s2);
    current.pixels = denormalize(current.normalized);
    if (!current.pixels.allFinite()) continue;
    current.score = score(current.pixels, &current.inliers);
    if (have_sample && !(current.score > best_sample_score)) continue;
    have_sample = true;
    best_sample_score = current.score;
    // Local optimisation: re-fit on the inliers while the score improves.
    for (int it = 0; it < refine_iterations; ++it) {
      int count = 0;
      for (std::uint8_t in : current.inliers) count += in;
      if (count <= kMinimalSetSize) break;
      trial.normalized = refit(current.normalized, current.inliers);
      trial.pixels = denormalize(trial.normalized);
      if (!trial.pixels.allFinite()) break;
      trial.score = score(trial.pixels, &trial.inliers);
      if (!(trial.score > current.score)) break;
      std::swap(current, trial);
      ++out.refinements;
    }
    if (!have_best || current.score > best.score) {
      have_best = true;
      std::swap(best, current);
    }
  }
  if (have_best) {
    out.matrix = best.pixels;
    out.score = best.score;
  }
  out.inliers = std::move(best.inliers);
  for (std::uint8_t in : out.inliers) out.num_inliers += in;
  return out;
}

}  // namespace

Eigen::Matrix3d RefineHomography(const std::vector<Eigen::Vector2d>& p1,
                                 const std::vector<Eigen::Vector2d>& p2,
                                 const std::vector<std::uint8_t>& inliers,
                                 const Eigen::Matrix3d& h21) {
  Matrix9 ata = Matrix9::Zero();
  Eigen::Matrix<double, 2, 9> rows;
  for (std::size_t i = 0; i < p1.size(); ++i) {
    if (!inliers[i]) continue;
    const double x1 = p1[i].x(), y1 = p1[i].y(), x2 = p2[i].x(), y2 = p2[i].y();
    // The DLT rows equal (h3 . p1) times the transfer error: divide that factor out.
    const double w3 = h21.row(2).dot(p1[i].homogeneous());
    if (!(std::abs(w3) > 1e-12)) continue;
    const double w = 1.0 / w3;
    rows.row(0) << 0, 0, 0, -x1, -y1, -1, y2 * x1, y2 * y1, y2;
    rows.row(1) << x1, y1, 1, 0, 0, 0, -x2 * x1, -x2 * y1, -x2;
    ata.noalias() += (w * w) * rows.transpose() * rows;
  }
  return Reshape(SmallestEigenvector(ata));
}

Eigen::Matrix3d RefineFundamental(const std::vector<Eigen::Vector2d>& p1,
                                  const std::vector<Eigen::Vector2d>& p2,
                                  const std::vector<std::uint8_t>& inliers,
                                  const Eigen::Matrix3d& f21) {
  Matrix9 ata = Matrix9::Zero();
  Vector9 row;
  for (std::size_t i = 0; i < p1.size(); ++i) {
    if (!inliers[i]) continue;
    const Eigen::Vector3d q1 = p1[i].homogeneous(), q2 = p2[i].homogeneous();
    // Sampson weighting: algebraic error / |gradient| ~ geometric distance.
    const Eigen::Vector3d l2 = f21 * q1, l1 = f21.transpose() * q2;
    const double g2 = l2.head<2>().squaredNorm() + l1.head<2>().squaredNorm();
    if (!(g2 > 1e-24)) continue;
    const double x1 = q1.x(), y1 = q1.y(), x2 = q2.x(), y2 = q2.y();
    row << x2 * x1, x2 * y1, x2, y2 * x1, y2 * y1, y2, x1, y1, 1;
    ata.noalias() += (1.0 / g2) * row * row.transpose();
  }
  return EnforceRankTwo(Reshape(SmallestEigenvector(ata)));
}

double HomographyShare(const Eigen::Matrix3d& h21, const Correspondences& c,
                       const std::vector<std::uint8_t>& mask, double sigma) {
  const Eigen::Matrix3d h12 = h21.inverse();
  const double gate = kChi2TwoDof99 * sigma * sigma;
  int total = 0, explained = 0;
  for (int i = 0; i < c.size(); ++i) {
    if (!mask[i]) continue;
    ++total;
    const Eigen::Vector2d& p1 = c.first[i];
    const Eigen::Vector2d& p2 = c.second[i];
    const double e2 = (p2 - (h21 * p1.homogeneous()).hnormalized()).squaredNorm();
    const double e1 = (p1 - (h12 * p2.homogeneous()).hnormalized()).squaredNorm();
    if (e1 <= gate && e2 <= gate) ++explained;
  }
  return total > 0 ? static_cast<double>(explained) / total : 0.0;
}

ModelFit RansacHomography(const Correspondences& c, const NormalizedPoints& normalized1,
                          const NormalizedPoints& normalized2, const std::vector<MinimalSet>& sets,
                          const RansacOptions& options) {
  const Eigen::Matrix3d t2_inv = normalized2.transform.inverse();
  return RunRansac(
      normalized1, normalized2, sets, options.refine_iterations, ComputeHomographyDlt,
      [&](const Eigen::Matrix3d& hn, const std::vector<std::uint8_t>& inliers) {
        return RefineHomography(normalized1.points, normalized2.points, inliers, hn);
      },
      [&](const Eigen::Matrix3d& hn) -> Eigen::Matrix3d {
        return t2_inv * hn * normalized1.transform;
      },
      [&](const Eigen::Matrix3d& h21, std::vector<std::uint8_t>* inliers) {
        return ScoreHomography(h21, h21.inverse(), c, options.sigma, inliers);
      },
      [](const MinimalSet&, const auto&, const auto&) { return false; });
}

ModelFit RansacFundamental(const Correspondences& c, const NormalizedPoints& normalized1,
                           const NormalizedPoints& normalized2, const std::vector<MinimalSet>& sets,
                           const RansacOptions& options) {
  const Eigen::Matrix3d t2_inv = normalized2.transform.inverse();
  return RunRansac(
      normalized1, normalized2, sets, options.refine_iterations, ComputeFundamentalEightPoint,
      [&](const Eigen::Matrix3d& fn, const std::vector<std::uint8_t>& inliers) {
        return RefineFundamental(normalized1.points, normalized2.points, inliers, fn);
      },
      [&](const Eigen::Matrix3d& fn) -> Eigen::Matrix3d {
        return normalized2.transform.transpose() * fn * normalized1.transform;
      },
      [&](const Eigen::Matrix3d& f21, std::vector<std::uint8_t>* inliers) {
        return ScoreFundamental(f21, c, options.sigma, inliers);
      },
      [&](const MinimalSet& set, const std::vector<Eigen::Vector2d>& s1,
          const std::vector<Eigen::Vector2d>& s2) {
        return options.reject_degenerate_samples &&
               SetFitsOneHomography(c, set, s1, s2, normalized1, t2_inv, options.sigma);
      });
}

namespace {

// Uniform integer in [0, range) from one 64-bit draw (multiply-shift; bias < 2^-32 for the
// ranges used here). Written out rather than std::uniform_int_distribution so the sets are
// the same with every standard library.
int UniformIndex(std::mt19937_64& rng, int range) {
  const std::uint64_t r = rng() >> 32;
  return static_cast<int>((r * static_cast<std::uint64_t>(range)) >> 32);
}

}  // namespace

// Partial Fisher-Yates on a running permutation (both models of the monocular initialiser
// share the sets).
std::vector<MinimalSet> DrawMinimalSets(int n, int iterations, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<int> pool(n);
  std::iota(pool.begin(), pool.end(), 0);
  std::vector<MinimalSet> sets(iterations);
  for (MinimalSet& set : sets) {
    for (int j = 0; j < kMinimalSetSize; ++j) {
      const int k = j + UniformIndex(rng, n - j);
      std::swap(pool[j], pool[k]);
      set[j] = pool[j];
    }
  }
  return sets;
}

}  // namespace pkslam::two_view
