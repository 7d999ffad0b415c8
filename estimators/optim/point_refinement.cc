#include "estimators/optim/point_refinement.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "core/util/error.h"

namespace pkslam {
namespace {

struct Obs {
  const BundleProblem::ObservationState* o;
  const SE3d* camera_from_world;
};

// Robust cost of a point's observations and (optionally) its normal equations.
double Cost(const BundleProblem& problem, const std::vector<Obs>& observations,
            const Eigen::Vector3d& p, const PointRefinementOptions& options, Eigen::Matrix3d* h,
            Eigen::Vector3d* b) {
  double cost = 0;
  if (h != nullptr) {
    h->setZero();
    b->setZero();
  }
  for (const Obs& ob : observations) {
    const BundleProblem::ObservationState& o = *ob.o;
    const Eigen::Vector3d pc = *ob.camera_from_world * p;
    if (!(pc.z() > 1e-6)) return std::numeric_limits<double>::infinity();
    const double iz = 1.0 / pc.z();
    const double u = problem.fx * pc.x() * iz + problem.cx;
    const double v = problem.fy * pc.y() * iz + problem.cy;
    const bool stereo = o.u_right >= 0;
    Eigen::Vector3d r(u - o.uv.x(), v - o.uv.y(), stereo ? u - problem.bf * iz - o.u_right : 0.0);
    const double chi2 = o.inv_sigma2 * r.squaredNorm();
    const double threshold = stereo ? options.chi2_stereo : options.chi2_mono;
    // Huber on the whitened norm: weight 1 inside, sqrt(threshold) / |r| outside.
    const double w = chi2 <= threshold ? 1.0 : std::sqrt(threshold / chi2);
    cost += chi2 <= threshold ? chi2 : 2 * std::sqrt(threshold * chi2) - threshold;
    if (h == nullptr) continue;
    Eigen::Matrix<double, 3, 3> d_pc;  // rows: u, v, u_right w.r.t. p_camera
    d_pc << problem.fx * iz, 0, -problem.fx * pc.x() * iz * iz,  //
        0, problem.fy * iz, -problem.fy * pc.y() * iz * iz,        //
        problem.fx * iz, 0, -problem.fx * pc.x() * iz * iz + problem.bf * iz * iz;
    const Eigen::Matrix3d j = d_pc * ob.camera_from_world->RotationMatrix();
    const int rows = stereo ? 3 : 2;
    const double weight = w * o.inv_sigma2;
    *h += weight * j.topRows(rows).transpose() * j.topRows(rows);
    *b += weight * j.topRows(rows).transpose() * r.head(rows);
  }
  return cost;
}

}  // namespace

void PointRefinementOptions::Check() const {
  PKSLAM_CHECK_OPTION(iterations >= 1, "point_refinement.iterations", "{}", iterations);
  PKSLAM_CHECK_OPTION(chi2_mono > 0 && chi2_stereo > 0, "point_refinement.chi2", "{} / {}",
                      chi2_mono, chi2_stereo);
}

std::vector<Eigen::Vector3d> RefinePoints(const BundleProblem& problem,
                                          const PointRefinementOptions& options) {
  options.Check();
  std::vector<Eigen::Vector3d> out;
  out.reserve(problem.points.size());
  for (const auto& p : problem.points) out.push_back(p.position_world);
  std::vector<std::vector<Obs>> by_point(problem.points.size());
  std::vector<int> rows(problem.points.size(), 0);
  for (const auto& o : problem.observations) {
    by_point[static_cast<std::size_t>(o.point_index)].push_back(
        {&o, &problem.keyframes[static_cast<std::size_t>(o.keyframe_index)].camera_from_world});
    rows[static_cast<std::size_t>(o.point_index)] += o.u_right >= 0 ? 3 : 2;
  }
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    if (rows[i] < 3) continue;
    Eigen::Vector3d p = out[i];
    Eigen::Matrix3d h;
    Eigen::Vector3d b;
    double cost = Cost(problem, by_point[i], p, options, &h, &b);
    if (!std::isfinite(cost)) continue;
    for (int it = 0; it < options.iterations; ++it) {
      const Eigen::LDLT<Eigen::Matrix3d> ldlt(h);
      if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) break;
      const Eigen::Vector3d step = ldlt.solve(-b);
      if (!step.allFinite()) break;
      const Eigen::Vector3d candidate = p + step;
      Eigen::Matrix3d h_next;
      Eigen::Vector3d b_next;
      const double next = Cost(problem, by_point[i], candidate, options, &h_next, &b_next);
      if (!(next < cost)) break;
      p = candidate;
      cost = next;
      h = h_next;
      b = b_next;
      if (step.norm() < 1e-7) break;
    }
    out[i] = p;
  }
  return out;
}

}  // namespace pkslam
