#include "keyframe/pks_math.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <nanoflann.hpp>
#include <numeric>

namespace pkslam::pks {
namespace {

// nanoflann dataset adaptor over a vector of points.
struct PointCloud {
  const std::vector<Eigen::Vector3d>& points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const { return points[i][dim]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox& /*bb*/) const {
    return false;
  }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloud>,
                                                   PointCloud, 3, std::size_t>;

constexpr double kRadToDeg = 180.0 / M_PI;

}  // namespace

std::vector<Eigen::Vector3d> EstimateNormals(const std::vector<Eigen::Vector3d>& points, int k,
                                             bool align_signs, std::span<const std::size_t> only) {
  const std::size_t n = points.size();
  std::vector<Eigen::Vector3d> normals(n, Eigen::Vector3d::Zero());
  if (k < 2 || n < static_cast<std::size_t>(k) + 1) return normals;
  const PointCloud cloud{points};
  const KdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  // A few spare neighbours so exact distance ties at the k-th place resolve by index.
  const std::size_t want = std::min(n, static_cast<std::size_t>(k) + 3);
  std::vector<std::size_t> indices(want);
  std::vector<double> distances(want);
  std::vector<std::pair<double, std::size_t>> candidates;
  std::vector<Eigen::Vector3d> offsets(k);
  std::vector<Eigen::Vector3d> crosses;
  const std::size_t count = only.empty() ? n : only.size();
  for (std::size_t q = 0; q < count; ++q) {
    const std::size_t i = only.empty() ? q : only[q];
    nanoflann::KNNResultSet<double, std::size_t> result(want);
    result.init(indices.data(), distances.data());
    tree.findNeighbors(result, points[i].data(), nanoflann::SearchParams());
    const std::size_t found = result.size();
    candidates.clear();
    for (std::size_t j = 0; j < found; ++j) {
      if (indices[j] != i) candidates.emplace_back(distances[j], indices[j]);
    }
    if (candidates.size() < static_cast<std::size_t>(k)) continue;
    std::sort(candidates.begin(), candidates.end());
    for (int j = 0; j < k; ++j) offsets[j] = points[candidates[j].second] - points[i];
    crosses.clear();
    for (int a = 0; a < k; ++a) {
      for (int b = a + 1; b < k; ++b) crosses.push_back(offsets[a].cross(offsets[b]));
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    if (align_signs) {
      const Eigen::Vector3d& ref = *std::max_element(
          crosses.begin(), crosses.end(), [](const Eigen::Vector3d& x, const Eigen::Vector3d& y) {
            return x.squaredNorm() < y.squaredNorm();
          });
      for (const auto& c : crosses) sum += c.dot(ref) >= 0 ? c : Eigen::Vector3d(-c);
    } else {
      for (const auto& c : crosses) sum += c;
    }
    const double norm = sum.norm();
    if (norm > 1e-12) normals[i] = sum / norm;
  }
  return normals;
}

double ViewAngleDeg(const Eigen::Vector3d& normal, const Eigen::Vector3d& point,
                    const Eigen::Vector3d& camera_center, bool released_z_flip) {
  const Eigen::Vector3d ray = camera_center - point;
  const double ray_norm = ray.norm();
  if (ray_norm <= 0 || normal.isZero()) return 0.0;
  const Eigen::Vector3d r = ray / ray_norm;
  double c = 0;
  if (released_z_flip) {
    c = normal.x() * r.x() + normal.y() * r.y() + std::abs(normal.z()) * r.z();
  } else {
    c = std::abs(normal.dot(r));
  }
  return std::acos(std::clamp(c, -1.0, 1.0)) * kRadToDeg;
}

int ConeRegion(double angle_deg, double width_deg, int regions) {
  if (angle_deg <= width_deg) return 0;
  const int r = static_cast<int>(std::ceil(angle_deg / width_deg)) - 1;
  return std::min(r, regions - 1);
}

AdaptiveThreshold ComputeAdaptiveThreshold(int a_c, int m_c, int d_c, int a_r, int m_r, int d_r,
                                           bool released) {
  AdaptiveThreshold t;
  if (m_r <= 0 || a_r <= 0 || m_c <= 0) return t;
  t.valid = true;
  const double mc = m_c, dc = d_c, ac = a_c, mr = m_r, dr = d_r, ar = a_r;
  t.th_initial = (mc * dr / mr + ac * dr / ar) / 2.0;  // Eq. 2
  t.theta = 1.0 - mc / mr;                             // Eq. 4
  t.beta = dc / mc - dr / mr;                          // Eq. 6
  t.alpha = dc / mc - 0.5;                             // Eq. 8
  if (released && 2 * m_c < m_r) t.gamma = (mr - 2 * mc) / (mr + 2 * mc);
  t.th_adaptive = t.th_initial * (1.0 + t.theta - t.beta - t.alpha - t.gamma);  // Eq. 1, 9
  if (released && t.theta < 0.1) t.th_adaptive = 1.1 * t.th_initial;
  return t;
}

Ecog ComputeEcog(const std::vector<int>& grid, int n, bool late_denominator) {
  Ecog e;
  const int cells = n * n;
  const long total = std::accumulate(grid.begin(), grid.begin() + cells, 0L);
  if (total <= 0) return e;
  e.valid = true;
  // Largest and second-largest cells; ties keep the first in row-major order.
  int i1 = 0;
  for (int i = 1; i < cells; ++i) {
    if (grid[i] > grid[i1]) i1 = i;
  }
  int i2 = -1;
  for (int i = 0; i < cells; ++i) {
    if (i == i1) continue;
    if (i2 < 0 || grid[i] > grid[i2]) i2 = i;
  }
  e.max1 = grid[i1];
  e.max2 = grid[i2];
  const double dr = i2 / n - i1 / n;
  const double dc = i2 % n - i1 % n;
  e.distance = std::sqrt(dr * dr + dc * dc);  // Eq. 11
  const double max_distance = (n - 1) * std::sqrt(2.0);
  const double denominator = late_denominator ? std::sqrt(2.0) * e.max1 : max_distance * e.max1;
  e.ecog = e.distance * e.max2 / denominator;  // Eq. 10
  // Centre of gravity with the outer rows/columns at -1 and +1.
  const double half = (n - 1) / 2.0;
  double sx = 0;
  double sy = 0;
  for (int i = 0; i < cells; ++i) {
    sx += grid[i] * ((i % n) - half) / half;
    sy += grid[i] * ((i / n) - half) / half;
  }
  e.xc = sx / static_cast<double>(total);
  e.yc = sy / static_cast<double>(total);
  e.cog = std::sqrt(e.xc * e.xc + e.yc * e.yc);  // Eq. 12
  return e;
}

int GridCell(double u, double v, int width, int height, int n) {
  const int col = std::clamp(static_cast<int>(u * n / width), 0, n - 1);
  const int row = std::clamp(static_cast<int>(v * n / height), 0, n - 1);
  return row * n + col;
}

std::optional<int> StrictGridCell(double u, double v, double min_x, double max_x, double min_y,
                                  double max_y, int n) {
  const double step_x = (max_x - min_x) / n;
  const double step_y = (max_y - min_y) / n;
  auto strict = [n](double x, double lo, double step) -> std::optional<int> {
    for (int c = 0; c < n; ++c) {
      if (x > lo + c * step && x < lo + (c + 1) * step) return c;
    }
    return std::nullopt;
  };
  const auto col = strict(u, min_x, step_x);
  const auto row = strict(v, min_y, step_y);
  if (!col || !row) return std::nullopt;
  return *row * n + *col;
}

int Counts::Effective() const { return std::accumulate(grid.begin(), grid.end(), 0); }

void TraceCounts(const Counts& counts, const std::string& suffix,
                 std::map<std::string, double>* trace) {
  (*trace)["A_" + suffix] = counts.a;
  (*trace)["M_" + suffix] = counts.m;
  (*trace)["D_" + suffix] = counts.d;
  if (suffix == "c") (*trace)["E_c"] = counts.Effective();
}

void TraceThreshold(const AdaptiveThreshold& threshold, bool released,
                    std::map<std::string, double>* trace) {
  if (!threshold.valid) return;
  auto& t = *trace;
  t["theta"] = threshold.theta;
  t["beta"] = threshold.beta;
  t["alpha"] = threshold.alpha;
  if (released) t["gamma"] = threshold.gamma;
  t["Th_initial"] = threshold.th_initial;
  t["Th_adaptive"] = threshold.th_adaptive;
}

void TraceEcog(const Ecog& ecog, std::map<std::string, double>* trace) {
  if (!ecog.valid) return;
  (*trace)["ECOG"] = ecog.ecog;
  (*trace)["COG"] = ecog.cog;
}

bool CameraCriterion(const Counts& c, const Counts& r, const CameraRule& rule,
                     std::map<std::string, double>* trace) {
  TraceCounts(r, "r", trace);
  const AdaptiveThreshold th =
      ComputeAdaptiveThreshold(c.a, c.m, c.d, r.a, r.m, r.d, rule.released);
  TraceThreshold(th, rule.released, trace);
  const bool criterion1 = rule.criterion1_allowed && th.valid && c.d > th.th_adaptive;
  const Ecog ecog = ComputeEcog(c.grid, rule.grid, rule.late_denominator);
  TraceEcog(ecog, trace);
  const bool criterion2 = ecog.valid && ecog.ecog > ecog.cog;
  (*trace)["criterion1"] = criterion1;
  (*trace)["criterion2"] = criterion2;
  return criterion1 && criterion2;
}

double ParallaxDeg(const Eigen::Vector3d& point, const Eigen::Vector3d& center_a,
                   const Eigen::Vector3d& center_b) {
  const Eigen::Vector3d a = center_a - point;
  const Eigen::Vector3d b = center_b - point;
  if (a.isZero() || b.isZero()) return 0.0;
  // atan2 of |a x b| and a.b stays accurate for the small angles between nearby cameras.
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
}

void ViewChangeDiagnostics::Add(double view_change, const Eigen::Vector3d& point,
                                const Eigen::Vector3d& keyframe_center,
                                const Eigen::Vector3d& center) {
  view_change_deg.push_back(view_change);
  parallax_deg.push_back(ParallaxDeg(point, keyframe_center, center));
}

void ViewChangeDiagnostics::Fill(std::map<std::string, double>* trace) const {
  auto quantiles = [trace](std::vector<double> v, const std::string& name) {
    if (v.empty()) return;
    std::sort(v.begin(), v.end());
    auto at = [&v](double q) { return v[static_cast<std::size_t>(q * (v.size() - 1) + 0.5)]; };
    (*trace)[name + "_p50"] = at(0.5);
    (*trace)[name + "_p90"] = at(0.9);
    (*trace)[name + "_max"] = v.back();
  };
  quantiles(view_change_deg, "view_change");
  quantiles(parallax_deg, "parallax");
}

}  // namespace pkslam::pks
