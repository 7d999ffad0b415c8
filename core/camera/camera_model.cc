#include "core/camera/camera_model.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "core/util/error.h"

namespace pkslam {
namespace {

using Matrix23d = Eigen::Matrix<double, 2, 3>;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Newton undistortion: iteration cap, step halvings per iteration, and the convergence
// threshold on the squared residual in normalised coordinates ((1e-12)^2, ~5e-10 px at f 500).
constexpr int kMaxNewtonIterations = 20;
constexpr int kMaxStepHalvings = 12;
constexpr double kUndistortTolSq = 1e-24;
// A Newton step shorter than 1e-9 (normalised) is taken as the last one.
constexpr double kFinalStepSq = 1e-18;
// KB8 theta solve: residual threshold on theta_d (normalised units) and iteration cap.
constexpr double kKbThetaTol = 1e-14;
constexpr int kMaxKbIterations = 40;

// Largest tan(angle) scanned when looking for the pinhole distortion fold (~87 degrees): no
// real pinhole lens sees further, so a fold beyond it does not matter.
constexpr double kMaxPinholeRadius = 20.0;

// Smallest x in (0, x_max] with f(x) <= 0, given f(0) > 0, or nullopt: a coarse scan then
// bisection. Returns the last x with f(x) > 0, so the result is inside the valid range.
template <typename F>
std::optional<double> FirstNonPositive(const F& f, double x_max) {
  constexpr int kScanSteps = 2000;
  double prev = 0.0;
  for (int i = 1; i <= kScanSteps; ++i) {
    const double x = x_max * i / kScanSteps;
    if (f(x) > 0.0) {
      prev = x;
      continue;
    }
    double lo = prev;
    double hi = x;
    for (int it = 0; it < 100 && hi - lo > 1e-15 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      (f(mid) > 0.0 ? lo : hi) = mid;
    }
    return lo;
  }
  return std::nullopt;
}

// OpenCV's radial-tangential distortion of the normalised point (x, y) -> (xd, yd) and, if
// j00 is given, its symmetric Jacobian [j00 j01; j01 j11]. S is double, or an Eigen array of
// several points (the batch path). c = k1 k2 p1 p2 k3.
template <typename S>
inline void RadTan(const std::array<double, 5>& c, const S& x, const S& y, S* xd, S* yd,
                   S* j00 = nullptr, S* j01 = nullptr, S* j11 = nullptr) {
  const double k1 = c[0], k2 = c[1], p1 = c[2], p2 = c[3], k3 = c[4];
  const S x2 = x * x, y2 = y * y, xy = x * y;
  const S r2 = x2 + y2;
  const S radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  *xd = x * radial + 2.0 * p1 * xy + p2 * (r2 + 2.0 * x2);
  *yd = y * radial + p1 * (r2 + 2.0 * y2) + 2.0 * p2 * xy;
  if (j00 != nullptr) {
    // d(radial)/d(r2); d(r2)/dx = 2x.
    const S d_radial = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2);
    *j00 = radial + 2.0 * x2 * d_radial + 2.0 * p1 * y + 6.0 * p2 * x;
    *j01 = 2.0 * xy * d_radial + 2.0 * p1 * x + 2.0 * p2 * y;
    *j11 = radial + 2.0 * y2 * d_radial + 6.0 * p1 * y + 2.0 * p2 * x;
  }
}

inline Eigen::Vector2d DistortRadTan(const std::array<double, 5>& c, const Eigen::Vector2d& p,
                                     Eigen::Matrix2d* jac) {
  Eigen::Vector2d d;
  if (jac == nullptr) {
    RadTan(c, p.x(), p.y(), &d.x(), &d.y());
  } else {
    RadTan(c, p.x(), p.y(), &d.x(), &d.y(), &(*jac)(0, 0), &(*jac)(0, 1), &(*jac)(1, 1));
    (*jac)(1, 0) = (*jac)(0, 1);
  }
  return d;
}

using Array4d = Eigen::Array<double, 4, 1>;

// Batch undistortion of four points (normalised coordinates): one radial fixed-point step, then
// kBatchNewtonSteps undamped Newton steps without branches, so the four dependency chains
// overlap in the CPU. Returns the squared residuals; the caller redoes lanes that did not
// converge with the robust scalar solver (about 1% of EuRoC pixels, all near the corners).
constexpr int kBatchNewtonSteps = 3;
Array4d UndistortBlock(const std::array<double, 5>& c, const Array4d& xd, const Array4d& yd,
                       Array4d* x, Array4d* y) {
  const Array4d rd2 = xd * xd + yd * yd;
  const Array4d inv_radial = (1.0 + rd2 * (c[0] + rd2 * (c[1] + rd2 * c[4]))).inverse();
  *x = xd * inv_radial;
  *y = yd * inv_radial;
  Array4d dx, dy, j00, j01, j11;
  for (int step = 0; step < kBatchNewtonSteps; ++step) {
    RadTan(c, *x, *y, &dx, &dy, &j00, &j01, &j11);
    const Array4d ex = dx - xd, ey = dy - yd;
    const Array4d inv_det = (j00 * j11 - j01 * j01).inverse();
    *x -= (j11 * ex - j01 * ey) * inv_det;
    *y -= (j00 * ey - j01 * ex) * inv_det;
  }
  RadTan(c, *x, *y, &dx, &dy);
  return (dx - xd).square() + (dy - yd).square();
}

// KB8 theta_d(theta) and its derivative. c = k1 k2 k3 k4.
inline double KbThetaD(const std::array<double, 5>& c, double theta) {
  const double t2 = theta * theta;
  return theta * (1.0 + t2 * (c[0] + t2 * (c[1] + t2 * (c[2] + t2 * c[3]))));
}
inline double KbThetaDDerivative(const std::array<double, 5>& c, double theta) {
  const double t2 = theta * theta;
  return 1.0 + t2 * (3.0 * c[0] + t2 * (5.0 * c[1] + t2 * (7.0 * c[2] + t2 * 9.0 * c[3])));
}

// Pinhole projection of a normalised point with d(uv)/d(p_camera) for the distortion-free case.
inline void PinholeJacobian(double fx, double fy, double inv_z, double x, double y,
                            Matrix23d* jac) {
  *jac << fx * inv_z, 0.0, -fx * x * inv_z, 0.0, fy * inv_z, -fy * y * inv_z;
}

void CheckIntrinsics(int width, int height, double fx, double fy, double cx, double cy) {
  PKSLAM_CHECK_OPTION(width > 0, "camera width", "got {}", width);
  PKSLAM_CHECK_OPTION(height > 0, "camera height", "got {}", height);
  PKSLAM_CHECK_OPTION(std::isfinite(fx) && fx > 0.0, "camera fx", "got {}", fx);
  PKSLAM_CHECK_OPTION(std::isfinite(fy) && fy > 0.0, "camera fy", "got {}", fy);
  PKSLAM_CHECK_OPTION(std::isfinite(cx), "camera cx", "got {}", cx);
  PKSLAM_CHECK_OPTION(std::isfinite(cy), "camera cy", "got {}", cy);
}

}  // namespace

CameraModel CameraModel::Pinhole(int width, int height, double fx, double fy, double cx, double cy,
                                 std::vector<double> distortion) {
  CheckIntrinsics(width, height, fx, fy, cx, cy);
  PKSLAM_CHECK_OPTION(distortion.empty() || distortion.size() == 4 || distortion.size() == 5,
                      "camera distortion",
                      "pinhole takes 0, 4 (k1 k2 p1 p2) or 5 (+k3) values, "
                      "got {}",
                      distortion.size());
  CameraModel cam;
  cam.type_ = CameraType::kPinhole;
  cam.width_ = width;
  cam.height_ = height;
  cam.fx_ = fx;
  cam.fy_ = fy;
  cam.cx_ = cx;
  cam.cy_ = cy;
  for (std::size_t i = 0; i < distortion.size(); ++i) {
    PKSLAM_CHECK_OPTION(std::isfinite(distortion[i]), "camera distortion", "coefficient {} is {}",
                        i, distortion[i]);
    cam.coeffs_[i] = distortion[i];
    cam.distorted_ = cam.distorted_ || distortion[i] != 0.0;
  }
  cam.distortion_ = std::move(distortion);

  // Radial fold: d(r * radial(r^2))/dr = 1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6 must stay > 0.
  const auto& c = cam.coeffs_;
  const auto fold = FirstNonPositive(
      [&c](double r) {
        const double r2 = r * r;
        return 1.0 + r2 * (3.0 * c[0] + r2 * (5.0 * c[1] + r2 * 7.0 * c[4]));
      },
      kMaxPinholeRadius);
  cam.max_r2_ = fold ? *fold * *fold : kInf;
  cam.max_theta_ = fold ? std::atan(*fold) : std::numbers::pi / 2;
  return cam;
}

CameraModel CameraModel::KannalaBrandt8(int width, int height, double fx, double fy, double cx,
                                        double cy, std::array<double, 4> distortion) {
  CheckIntrinsics(width, height, fx, fy, cx, cy);
  CameraModel cam;
  cam.type_ = CameraType::kKannalaBrandt8;
  cam.width_ = width;
  cam.height_ = height;
  cam.fx_ = fx;
  cam.fy_ = fy;
  cam.cx_ = cx;
  cam.cy_ = cy;
  for (std::size_t i = 0; i < distortion.size(); ++i) {
    PKSLAM_CHECK_OPTION(std::isfinite(distortion[i]), "camera distortion", "coefficient {} is {}",
                        i, distortion[i]);
    cam.coeffs_[i] = distortion[i];
  }
  cam.distortion_.assign(distortion.begin(), distortion.end());
  // KB8 is a different mapping from the pinhole even with all-zero coefficients.
  cam.distorted_ = true;
  const auto& c = cam.coeffs_;
  const auto fold = FirstNonPositive([&c](double theta) { return KbThetaDDerivative(c, theta); },
                                     std::numbers::pi);
  cam.max_theta_ = fold.value_or(std::numbers::pi);
  cam.max_theta_d_ = KbThetaD(c, cam.max_theta_);
  cam.max_r2_ = kInf;
  return cam;
}

bool CameraModel::HasDistortion() const { return distorted_; }

std::optional<Eigen::Vector2d> CameraModel::Project(const Eigen::Vector3d& p_camera,
                                                    Matrix23d* d_uv_d_p) const {
  const double x = p_camera.x(), y = p_camera.y(), z = p_camera.z();
  if (type_ == CameraType::kPinhole) {
    if (!(z > projection::kMinDepth)) return std::nullopt;
    const double inv_z = 1.0 / z;
    const Eigen::Vector2d xy(x * inv_z, y * inv_z);
    if (!distorted_) {
      if (d_uv_d_p != nullptr) PinholeJacobian(fx_, fy_, inv_z, xy.x(), xy.y(), d_uv_d_p);
      return Eigen::Vector2d(fx_ * xy.x() + cx_, fy_ * xy.y() + cy_);
    }
    if (xy.squaredNorm() > max_r2_) return std::nullopt;
    Eigen::Matrix2d d_dist;
    const Eigen::Vector2d dist = DistortRadTan(coeffs_, xy, d_uv_d_p ? &d_dist : nullptr);
    if (d_uv_d_p != nullptr) {
      Matrix23d d_xy_d_p;
      d_xy_d_p << inv_z, 0.0, -xy.x() * inv_z, 0.0, inv_z, -xy.y() * inv_z;
      *d_uv_d_p = Eigen::Vector2d(fx_, fy_).asDiagonal() * d_dist * d_xy_d_p;
    }
    return Eigen::Vector2d(fx_ * dist.x() + cx_, fy_ * dist.y() + cy_);
  }

  // Kannala-Brandt 8.
  const double r2 = x * x + y * y;
  if (!(r2 > projection::kKbAxisRatioSq * z * z)) {
    // On the optical axis the model is the pinhole to first order.
    if (!(z > 0.0)) return std::nullopt;
    const double inv_z = 1.0 / z;
    if (d_uv_d_p != nullptr) PinholeJacobian(fx_, fy_, inv_z, x * inv_z, y * inv_z, d_uv_d_p);
    return Eigen::Vector2d(fx_ * x * inv_z + cx_, fy_ * y * inv_z + cy_);
  }
  const double r = std::sqrt(r2);
  const double theta = std::atan2(r, z);
  if (theta > max_theta_) return std::nullopt;
  const double s = KbThetaD(coeffs_, theta) / r;
  if (d_uv_d_p != nullptr) {
    const double n2 = r2 + z * z;
    const double d_thd = KbThetaDDerivative(coeffs_, theta);
    // s = theta_d / r; ds/dr = (theta_d' * dtheta/dr - s) / r with dtheta/dr = z / n2.
    const double a = (d_thd * z / n2 - s) / r2;                          // (ds/dr) / r
    const double d_z = -d_thd / n2;                                      // theta_d' * dtheta/dz / r
    *d_uv_d_p << fx_ * (s + a * x * x), fx_ * a * x * y, fx_ * x * d_z,  //
        fy_ * a * x * y, fy_ * (s + a * y * y), fy_ * y * d_z;
  }
  return Eigen::Vector2d(fx_ * s * x + cx_, fy_ * s * y + cy_);
}

Eigen::Vector2d CameraModel::UndistortNormalized(double xd, double yd) const {
  const Eigen::Vector2d target(xd, yd);
  if (!distorted_) return target;
  // Initial guess: two fixed-point steps of the radial part alone (p = target / radial(|p|)).
  // For EuRoC this starts within ~1e-3 of the answer, so Newton needs ~2 steps.
  const auto& c = coeffs_;
  const auto radial = [&c](double r2) { return 1.0 + r2 * (c[0] + r2 * (c[1] + r2 * c[4])); };
  Eigen::Vector2d p = target;
  for (int i = 0; i < 2; ++i) {
    const double factor = radial(p.squaredNorm());
    if (!(factor > 0.2)) break;  // far outside a sane image: leave it to Newton
    p = target / factor;
  }
  if (p.squaredNorm() > max_r2_) p *= std::sqrt(max_r2_ / p.squaredNorm());

  Eigen::Matrix2d jac;
  Eigen::Vector2d err = DistortRadTan(c, p, &jac) - target;
  double err2 = err.squaredNorm();
  for (int it = 0; it < kMaxNewtonIterations && err2 > kUndistortTolSq; ++it) {
    const double det = jac(0, 0) * jac(1, 1) - jac(0, 1) * jac(1, 0);
    if (!(std::abs(det) > 1e-12)) break;  // at the fold; cannot improve
    const Eigen::Vector2d delta(-(jac(1, 1) * err.x() - jac(0, 1) * err.y()) / det,
                                -(jac(0, 0) * err.y() - jac(1, 0) * err.x()) / det);
    if (delta.squaredNorm() < kFinalStepSq) {
      // Newton converges quadratically: after so small a step the residual is ~|delta|^2,
      // far below the tolerance, so the verifying evaluation can be skipped.
      p += delta;
      break;
    }
    // Backtracking keeps every accepted step a decrease of the residual (robust far out).
    bool improved = false;
    double alpha = 1.0;
    for (int h = 0; h < kMaxStepHalvings && !improved; ++h, alpha *= 0.5) {
      const Eigen::Vector2d candidate = p + alpha * delta;
      if (candidate.squaredNorm() > max_r2_) continue;
      Eigen::Matrix2d jac_c;
      const Eigen::Vector2d err_c = DistortRadTan(c, candidate, &jac_c) - target;
      const double err2_c = err_c.squaredNorm();
      if (err2_c < err2) {
        p = candidate;
        jac = jac_c;
        err = err_c;
        err2 = err2_c;
        improved = true;
      }
    }
    if (!improved) break;  // converged to rounding level
  }
  return p;
}

double CameraModel::SolveKbTheta(double rd) const {
  if (!(rd > 0.0)) return 0.0;
  if (rd >= max_theta_d_) return max_theta_;
  // theta_d is increasing on [0, max_theta_]: Newton safeguarded by a shrinking bracket.
  double lo = 0.0, hi = max_theta_;
  double theta = std::min(rd, max_theta_);  // theta_d ~= theta for mild distortion
  for (int it = 0; it < kMaxKbIterations; ++it) {
    const double f = KbThetaD(coeffs_, theta) - rd;
    if (std::abs(f) < kKbThetaTol) break;
    (f > 0.0 ? hi : lo) = theta;
    double next = theta - f / KbThetaDDerivative(coeffs_, theta);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (next == theta) break;
    theta = next;
  }
  return theta;
}

Eigen::Vector3d CameraModel::Unproject(const Eigen::Vector2d& uv) const {
  const double mx = (uv.x() - cx_) / fx_;
  const double my = (uv.y() - cy_) / fy_;
  if (type_ == CameraType::kPinhole) {
    const Eigen::Vector2d p = UndistortNormalized(mx, my);
    return Eigen::Vector3d(p.x(), p.y(), 1.0).normalized();
  }
  const double rd = std::hypot(mx, my);
  if (!(rd > 0.0)) return Eigen::Vector3d::UnitZ();
  const double theta = SolveKbTheta(rd);
  const double s = std::sin(theta) / rd;
  return Eigen::Vector3d(mx * s, my * s, std::cos(theta));
}

Eigen::Vector2d CameraModel::UndistortPixel(const Eigen::Vector2d& uv) const {
  const double mx = (uv.x() - cx_) / fx_;
  const double my = (uv.y() - cy_) / fy_;
  if (type_ == CameraType::kPinhole) {
    if (!distorted_) return uv;
    const Eigen::Vector2d p = UndistortNormalized(mx, my);
    return Eigen::Vector2d(fx_ * p.x() + cx_, fy_ * p.y() + cy_);
  }
  const double rd = std::hypot(mx, my);
  if (!(rd > 0.0)) return uv;
  const double theta = SolveKbTheta(rd);
  if (!(std::cos(theta) > projection::kMinDepth)) return Eigen::Vector2d(kNaN, kNaN);
  const double s = std::tan(theta) / rd;
  return Eigen::Vector2d(fx_ * mx * s + cx_, fy_ * my * s + cy_);
}

void CameraModel::UndistortPixels(const std::vector<cv::Point2f>& in,
                                  std::vector<cv::Point2f>* out) const {
  PKSLAM_CHECK(out != nullptr && out != &in, "UndistortPixels needs a distinct output vector");
  if (type_ == CameraType::kPinhole && !distorted_) {
    *out = in;
    return;
  }
  out->resize(in.size());
  if (type_ == CameraType::kPinhole) {
    const double inv_fx = 1.0 / fx_, inv_fy = 1.0 / fy_;
    const auto write = [&](std::size_t i, double x, double y) {
      (*out)[i] = cv::Point2f(static_cast<float>(fx_ * x + cx_), static_cast<float>(fy_ * y + cy_));
    };
    std::size_t i = 0;
    for (; i + 4 <= in.size(); i += 4) {
      Array4d xd, yd, x, y;
      for (int k = 0; k < 4; ++k) {
        xd[k] = (in[i + k].x - cx_) * inv_fx;
        yd[k] = (in[i + k].y - cy_) * inv_fy;
      }
      const Array4d res2 = UndistortBlock(coeffs_, xd, yd, &x, &y);
      for (int k = 0; k < 4; ++k) {
        // Also redo lanes that converged to a root beyond the fold (the scalar path never goes
        // there), so batch and single results agree.
        if (res2[k] <= kUndistortTolSq && x[k] * x[k] + y[k] * y[k] <= max_r2_) {
          write(i + k, x[k], y[k]);
        } else {
          const Eigen::Vector2d p = UndistortNormalized(xd[k], yd[k]);
          write(i + k, p.x(), p.y());
        }
      }
    }
    for (; i < in.size(); ++i) {
      const Eigen::Vector2d p =
          UndistortNormalized((in[i].x - cx_) * inv_fx, (in[i].y - cy_) * inv_fy);
      write(i, p.x(), p.y());
    }
    return;
  }
  for (std::size_t i = 0; i < in.size(); ++i) {
    const Eigen::Vector2d u = UndistortPixel(Eigen::Vector2d(in[i].x, in[i].y));
    (*out)[i] = cv::Point2f(static_cast<float>(u.x()), static_cast<float>(u.y()));
  }
}

bool CameraModel::InImage(const Eigen::Vector2d& uv, double border) const {
  return uv.x() >= border - 0.5 && uv.x() < width_ - 0.5 - border && uv.y() >= border - 0.5 &&
         uv.y() < height_ - 0.5 - border;
}

Eigen::Matrix3d CameraModel::K() const {
  Eigen::Matrix3d k;
  k << fx_, 0.0, cx_, 0.0, fy_, cy_, 0.0, 0.0, 1.0;
  return k;
}

cv::Mat CameraModel::CvK() const {
  return (cv::Mat_<double>(3, 3) << fx_, 0.0, cx_, 0.0, fy_, cy_, 0.0, 0.0, 1.0);
}

cv::Mat CameraModel::CvDistortion() const {
  if (distortion_.empty()) return cv::Mat::zeros(1, 4, CV_64F);
  cv::Mat d(1, static_cast<int>(distortion_.size()), CV_64F);
  for (std::size_t i = 0; i < distortion_.size(); ++i) {
    d.at<double>(0, static_cast<int>(i)) = distortion_[i];
  }
  return d;
}

std::array<double, 9> CameraModel::Params() const {
  return {fx_, fy_, cx_, cy_, coeffs_[0], coeffs_[1], coeffs_[2], coeffs_[3], coeffs_[4]};
}

std::string CameraModel::ToString() const {
  const char* name = type_ == CameraType::kPinhole
                         ? (distortion_.empty() ? "pinhole" : "pinhole-radtan")
                         : "kannala-brandt8";
  std::string text =
      fmt::format("{} {}x{} fx={} fy={} cx={} cy={}", name, width_, height_, fx_, fy_, cx_, cy_);
  if (!distortion_.empty()) {
    const char* label = type_ == CameraType::kPinhole ? "k1,k2,p1,p2[,k3]" : "k1..k4";
    text += fmt::format(" {}=[{}]", label, fmt::join(distortion_, ", "));
  }
  return text;
}

}  // namespace pkslam
