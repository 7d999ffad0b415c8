#include "io/kitti_dataset.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/text_rows.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

// The image stream of folder `dir` (NNNNNN.png per frame) for the stamps; frames whose file is
// missing are listed as missing, as the EuRoC reader lists them.
ImageStream ReadKittiImages(const fs::path& dir, const std::string& name,
                            const std::vector<std::int64_t>& t_ns) {
  ImageStream s;
  s.name = name;
  s.list_file = dir.parent_path() / "times.txt";  // the list the frames come from
  s.listed = t_ns.size();
  for (std::size_t i = 0; i < t_ns.size(); ++i) {
    fs::path file = dir / fmt::format("{:06d}.png", i);
    if (fs::exists(file)) {
      s.images.push_back({t_ns[i], std::move(file)});
    } else {
      s.missing.push_back(std::move(file));
    }
  }
  return s;
}

// calib.txt: "NAME: 12 numbers" per line.
std::map<std::string, std::vector<double>> ReadCalib(const fs::path& file) {
  std::map<std::string, std::vector<double>> out;
  ForEachDataRow(file, FieldSeparator::kWhitespace, [&](const TextRow& row) {
    std::string name(row.fields.front());
    if (name.empty() || name.back() != ':') {
      throw InputError(file, row.line, fmt::format("expected 'NAME: 12 numbers', got '{}'", name));
    }
    name.pop_back();
    RequireFieldCount(row, 13, file, "NAME: 12 numbers (a 3x4 matrix, row-major)");
    std::vector<double> m;
    for (std::size_t k = 1; k < row.fields.size(); ++k) {
      m.push_back(DoubleField(row.fields[k], file, row.line, name));
    }
    out[name] = std::move(m);
  });
  return out;
}

}  // namespace

bool LooksLikeKitti(const fs::path& root) {
  return fs::is_regular_file(root / "times.txt") && fs::is_regular_file(root / "calib.txt") &&
         (fs::is_directory(root / "image_0") || fs::is_directory(root / "image_2"));
}

std::vector<std::int64_t> ReadKittiTimes(const fs::path& times_txt) {
  std::vector<std::int64_t> t_ns;
  std::optional<std::int64_t> previous;
  ForEachDataRow(times_txt, FieldSeparator::kWhitespace, [&](const TextRow& row) {
    RequireFieldCount(row, 1, times_txt, "one time in seconds per frame");
    const double t = DoubleField(row.fields[0], times_txt, row.line, "time");
    const std::int64_t ns = std::llround(t * 1e9);
    RequireIncreasing(previous, ns, times_txt, row.line);
    previous = ns;
    t_ns.push_back(ns);
  });
  if (t_ns.empty()) throw InputError(times_txt, "no times");
  return t_ns;
}

KittiSequence OpenKittiSequence(const fs::path& root, const KittiOptions& options) {
  KittiSequence s;
  s.root = root;
  s.colour = options.colour;
  const std::vector<std::int64_t> t_ns = ReadKittiTimes(root / "times.txt");
  const std::string left = options.colour ? "image_2" : "image_0";
  const std::string right = options.colour ? "image_3" : "image_1";
  if (!fs::is_directory(root / left)) {
    throw InputError(root / left, options.colour ? "missing (the colour pair was asked for)"
                                                 : "missing (the grey left images)");
  }
  s.left = ReadKittiImages(root / left, "cam0", t_ns);
  if (s.left.images.empty()) throw InputError(root / left, "no NNNNNN.png image of times.txt");
  if (fs::is_directory(root / right)) s.right = ReadKittiImages(root / right, "cam1", t_ns);

  const fs::path calib = root / "calib.txt";
  const auto matrices = ReadCalib(calib);
  const std::string p_left = options.colour ? "P2" : "P0";
  const std::string p_right = options.colour ? "P3" : "P1";
  for (const std::string& key : {p_left, p_right}) {
    if (!matrices.count(key)) throw InputError(calib, fmt::format("no {} line", key));
  }
  const std::vector<double>& pl = matrices.at(p_left);
  const std::vector<double>& pr = matrices.at(p_right);
  s.fx = pl[0];
  s.fy = pl[5];
  s.cx = pl[2];
  s.cy = pl[6];
  if (!(s.fx > 0 && s.fy > 0))
    throw InputError(calib, fmt::format("{}: focal length <= 0", p_left));
  // Rectified: both share K; their translations differ by -fx b along x (the colour cameras
  // also carry a small offset to camera 0, which the difference removes).
  const double same_k = std::abs(pr[0] - pl[0]) + std::abs(pr[5] - pl[5]) +
                        std::abs(pr[2] - pl[2]) + std::abs(pr[6] - pl[6]);
  if (same_k > 1e-6 * s.fx) {
    throw InputError(calib, fmt::format("{} and {} have different intrinsics: not a rectified "
                                        "pair",
                                        p_left, p_right));
  }
  s.baseline_m = (pl[3] - pr[3]) / s.fx;
  if (!(s.baseline_m > 0)) {
    throw InputError(calib, fmt::format("{} is not to the right of {} (baseline {} m)", p_right,
                                        p_left, s.baseline_m));
  }
  const cv::Mat first = LoadGreyImage(s.left.images.front().path);
  s.width = first.cols;
  s.height = first.rows;
  std::vector<std::int64_t> dt;
  for (std::size_t i = 1; i < t_ns.size(); ++i) dt.push_back(t_ns[i] - t_ns[i - 1]);
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  s.rate_hz = dt.empty() ? 10.0 : 1e9 / static_cast<double>(dt[dt.size() / 2]);
  return s;
}

Settings SettingsFromKitti(const KittiSequence& k) {
  Settings s;
  s.camera1 = CameraModel::Pinhole(k.width, k.height, k.fx, k.fy, k.cx, k.cy);
  s.fps = k.rate_hz;
  if (!k.right.images.empty()) {
    s.rectified_stereo = true;
    s.stereo_baseline_m = k.baseline_m;
    s.right_from_left = SE3d(SO3d(), Eigen::Vector3d(-k.baseline_m, 0, 0));
  }
  s.th_depth = 40;  // ORB-SLAM3's KITTI settings
  s.orb.n_features = 2000;
  s.Check();
  return s;
}

Trajectory ReadKittiPoses(const fs::path& poses_txt, const std::vector<std::int64_t>& t_ns) {
  Trajectory out;
  out.source = poses_txt;
  ForEachDataRow(poses_txt, FieldSeparator::kWhitespace, [&](const TextRow& row) {
    RequireFieldCount(row, 12, poses_txt, "12 numbers: world_from_cam0 as 3x4, row-major");
    Eigen::Matrix<double, 3, 4> m;
    for (int k = 0; k < 12; ++k) {
      m(k / 4, k % 4) =
          DoubleField(row.fields[static_cast<std::size_t>(k)], poses_txt, row.line, "pose");
    }
    const Eigen::Matrix3d r = m.leftCols<3>();
    // KITTI prints 6-7 significant digits: the rotation is orthonormal to about 1e-6, so it is
    // projected onto the nearest rotation unless it is clearly not one.
    const SO3d rotation = SO3d::FitToMatrix(r);
    if ((rotation.Matrix() - r).cwiseAbs().maxCoeff() > 1e-3) {
      throw InputError(poses_txt, row.line, "the 3x3 block is not a rotation");
    }
    if (out.poses.size() >= t_ns.size()) {
      throw InputError(poses_txt, row.line,
                       fmt::format("more poses than the {} times of times.txt", t_ns.size()));
    }
    out.poses.push_back({t_ns[out.poses.size()], SE3d(rotation, m.col(3))});
  });
  if (out.poses.size() != t_ns.size()) {
    throw InputError(poses_txt, fmt::format("{} poses for {} times (times.txt): one per frame",
                                            out.poses.size(), t_ns.size()));
  }
  return out;
}

fs::path KittiTimesFor(const fs::path& poses_txt) {
  const fs::path candidate =
      poses_txt.parent_path().parent_path() / "sequences" / poses_txt.stem() / "times.txt";
  return fs::exists(candidate) ? candidate : fs::path();
}

void WriteKittiPoses(const Trajectory& trajectory, const fs::path& file) {
  OutputFile out(file);
  for (const StampedPose& p : trajectory.poses) {
    const Eigen::Matrix3d r = p.pose.so3().Matrix();
    const Eigen::Vector3d t = p.pose.translation();
    out.stream() << fmt::format(
        "{:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} {:.9e} "
        "{:.9e} {:.9e} {:.9e}\n",
        r(0, 0), r(0, 1), r(0, 2), t.x(), r(1, 0), r(1, 1), r(1, 2), t.y(), r(2, 0), r(2, 1),
        r(2, 2), t.z());
  }
  out.Commit();
}

}  // namespace pkslam
