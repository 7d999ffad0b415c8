// The photogrammetric quantities of PKS (../shared/docs/PKS.md), as pure functions so each
// equation can be tested on hand-worked numbers.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace pkslam::pks {

// Surface normal of every point from its k nearest other points (3-D distance; ties to the
// lower index): n = normalize(sum_{a<b} v_a x v_b) over the k(k-1)/2 neighbour pairs, v = the
// offsets to the neighbours (the released code's formula). That raw sum cancels for symmetric
// neighbourhoods (+x, -x, +y, -y gives 0); with align_signs each cross product is first
// turned into the hemisphere of the largest one, which keeps the normal an (unoriented) axis
// and never cancels on a surface. A point gets a zero normal when fewer than k other points
// exist or the sum vanishes. k-d tree (nanoflann). With `only` non-empty, normals are computed
// for those indices alone (neighbours still come from all points); the others stay zero.
std::vector<Eigen::Vector3d> EstimateNormals(const std::vector<Eigen::Vector3d>& points, int k = 5,
                                             bool align_signs = true,
                                             std::span<const std::size_t> only = {});

// Angle (degrees) between a point's normal and the ray from the point to the camera centre.
// fold = true treats the normal as an unoriented axis (angle in [0, 90]); the released code
// instead reflects the normal to world z >= 0 (released_z_flip) and gets [0, 180].
double ViewAngleDeg(const Eigen::Vector3d& normal, const Eigen::Vector3d& point,
                    const Eigen::Vector3d& camera_center, bool released_z_flip);

// Cone region of a viewing angle: (0, w] -> 0, (w, 2w] -> 1, ..., everything beyond
// (regions - 1) * w -> regions - 1.
int ConeRegion(double angle_deg, double width_deg, int regions);

// Eq. 1-9: the adaptive threshold on D_c from the current frame (c) and the reference frame
// (r: the first frame after the last keyframe). A = tracked points, M = points matched to the
// last keyframe, D = matched points whose cone region changed.
struct AdaptiveThreshold {
  bool valid = false;      // false when M_r, A_r or M_c is 0 (ratios undefined)
  double th_initial = 0;   // Eq. 2
  double theta = 0;        // Eq. 4
  double beta = 0;         // Eq. 6
  double alpha = 0;        // Eq. 8
  double gamma = 0;        // released code only
  double th_adaptive = 0;  // Eq. 1 / 9 (released: minus gamma, theta < 0.1 clamp)
};
AdaptiveThreshold ComputeAdaptiveThreshold(int a_c, int m_c, int d_c, int a_r, int m_r, int d_r,
                                           bool released);

// Eq. 10-12 on an n x n grid of effective-point counts (row-major). ECOG = d * max2 /
// (D * max1) with D the largest cell distance ((n-1) * sqrt 2, = 2 sqrt 2 for 3x3; the released
// code's late denominator is sqrt 2 * max1: pass late_denominator). |COG| from the grid's
// centre of gravity with outer rows/columns at +-1. Ties for max: first in row-major order.
struct Ecog {
  bool valid = false;  // false for an all-zero grid
  double ecog = 0;
  double cog = 0;  // |COG|
  double xc = 0;
  double yc = 0;
  int max1 = 0;
  int max2 = 0;
  double distance = 0;  // d, in cells
};
Ecog ComputeEcog(const std::vector<int>& grid, int n, bool late_denominator);

// Grid cell (row-major index) of an image point on an n x n grid over width x height.
int GridCell(double u, double v, int width, int height, int n);

// The released code's binning over the undistorted image bounds [min, max]: column c when
// min_x + c * step < u < min_x + (c + 1) * step (strictly), rows alike; a point on a cell
// border or outside the bounds falls in no cell (nullopt).
std::optional<int> StrictGridCell(double u, double v, double min_x, double max_x, double min_y,
                                  double max_y, int n);

// One frame's counts: A tracked points, M matched to the last keyframe, D matched with a
// changed cone region, and the effective points per grid cell (row-major).
struct Counts {
  int a = 0;
  int m = 0;
  int d = 0;
  std::vector<int> grid;
  int Effective() const;
};

// Trace rows (keyframe_trace.csv columns): A_/M_/D_ with `suffix` ("c" or "r") and E_c; the
// threshold's terms (gamma only for the released code); ECOG and |COG| when valid.
void TraceCounts(const Counts& counts, const std::string& suffix,
                 std::map<std::string, double>* trace);
void TraceThreshold(const AdaptiveThreshold& threshold, bool released,
                    std::map<std::string, double>* trace);
void TraceEcog(const Ecog& ecog, std::map<std::string, double>* trace);

// The camera decision from the frame's (c) and the reference's (r) counts: criterion 1
// (D_c > Th_adaptive, Eq. 1-9; the released code's form with `released`) AND criterion 2
// (ECOG > |COG|, Eq. 10-12, with the late denominator when asked). `criterion1_allowed` false
// vetoes criterion 1 (the released code's frames > 1). Traces r's counts, the terms and both
// criteria.
struct CameraRule {
  bool released = false;
  bool late_denominator = false;
  bool criterion1_allowed = true;
  int grid = 3;
};
bool CameraCriterion(const Counts& c, const Counts& r, const CameraRule& rule,
                     std::map<std::string, double>* trace);

// Why delta is (un)reachable: for a normal fixed at the keyframe, a point's viewing-angle change
// between the keyframe and the frame is at most the parallax angle between the two rays to it
// (triangle inequality on the sphere). Collects both per matched point of one frame; Fill
// writes their 50th/90th percentiles and maxima (degrees) into a trace row.
struct ViewChangeDiagnostics {
  std::vector<double> view_change_deg;
  std::vector<double> parallax_deg;
  void Add(double view_change, const Eigen::Vector3d& point, const Eigen::Vector3d& keyframe_center,
           const Eigen::Vector3d& center);
  void Fill(std::map<std::string, double>* trace) const;
};

// Angle (degrees) between the rays from `point` to two camera centres.
double ParallaxDeg(const Eigen::Vector3d& point, const Eigen::Vector3d& center_a,
                   const Eigen::Vector3d& center_b);

}  // namespace pkslam::pks
