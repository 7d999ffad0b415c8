#include "dense/colmap_export.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <unordered_map>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "core/util/progress.h"

namespace pkslam::dense {

namespace fs = std::filesystem;

namespace {

// COLMAP's pixel convention puts the top-left pixel's centre at (0.5, 0.5).
constexpr double kColmapPixelShift = 0.5;

}  // namespace

void ColmapExportOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_track_length >= 1, "--min-track-length", "{}", min_track_length);
}

ColmapExportStats WriteColmapText(const SparseModel& model,
                                  const std::vector<std::string>& image_names,
                                  const std::vector<Rgb>& point_colours,
                                  const ColmapExportOptions& options, const fs::path& sparse_dir) {
  options.Check();
  PKSLAM_CHECK(image_names.size() == model.keyframes.size(), "{} names for {} keyframes",
               image_names.size(), model.keyframes.size());
  PKSLAM_CHECK(point_colours.empty() || point_colours.size() == model.points.size(),
               "{} colours for {} points", point_colours.size(), model.points.size());
  fs::create_directories(sparse_dir);
  ColmapExportStats stats;
  const SparseCamera& cam = model.camera;

  std::unordered_map<std::int64_t, int> image_id;  // keyframe id -> COLMAP image id
  for (std::size_t i = 0; i < model.keyframes.size(); ++i) {
    image_id[model.keyframes[i].id] = static_cast<int>(i) + 1;
  }
  std::unordered_map<std::int64_t, const SparsePoint*> exported;  // by map point id
  for (const SparsePoint& p : model.points) {
    if (static_cast<int>(p.observations.size()) >= options.min_track_length) {
      exported[p.id] = &p;
    } else {
      ++stats.points_dropped;
    }
  }

  {
    OutputFile output(sparse_dir / "cameras.txt");
    std::ostream& out = output.stream();
    out << "# Camera list with one line of data per camera:\n"
        << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n# Number of cameras: 1\n"
        << fmt::format("1 PINHOLE {} {} {:.9g} {:.9g} {:.9g} {:.9g}\n", cam.width, cam.height,
                       cam.fx, cam.fy, cam.cx + kColmapPixelShift, cam.cy + kColmapPixelShift);
    output.Commit();
  }
  {
    OutputFile output(sparse_dir / "images.txt");
    std::ostream& out = output.stream();
    std::size_t observations = 0;
    for (const SparseKeyframe& kf : model.keyframes) {
      for (const SparseKeypoint& k : kf.keypoints) observations += exported.count(k.point_id);
    }
    out << "# Image list with two lines of data per image:\n"
        << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
        << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
        << fmt::format("# Number of images: {}, mean observations per image: {:.6g}\n",
                       model.keyframes.size(),
                       model.keyframes.empty() ? 0.0
                                               : static_cast<double>(observations) /
                                                     static_cast<double>(model.keyframes.size()));
    fmt::memory_buffer b;
    for (std::size_t i = 0; i < model.keyframes.size(); ++i) {
      const SparseKeyframe& kf = model.keyframes[i];
      const Eigen::Quaterniond& q = kf.camera_from_world.quaternion();
      const Eigen::Vector3d& t = kf.camera_from_world.translation();
      fmt::format_to(std::back_inserter(b),
                     "{} {:.12f} {:.12f} {:.12f} {:.12f} {:.9f} {:.9f} {:.9f} 1 {}\n", i + 1, q.w(),
                     q.x(), q.y(), q.z(), t.x(), t.y(), t.z(), image_names[i]);
      for (std::size_t k = 0; k < kf.keypoints.size(); ++k) {
        const SparseKeypoint& kp = kf.keypoints[k];
        const std::int64_t id = exported.count(kp.point_id) > 0 ? kp.point_id + 1 : -1;
        fmt::format_to(std::back_inserter(b), "{}{:.4f} {:.4f} {}", k == 0 ? "" : " ",
                       kp.u + kColmapPixelShift, kp.v + kColmapPixelShift, id);
      }
      b.push_back('\n');
    }
    out.write(b.data(), static_cast<std::streamsize>(b.size()));
    output.Commit();
    stats.observations = observations;
  }
  {
    std::unordered_map<std::int64_t, const SparseKeyframe*> keyframe_by_id;
    for (const SparseKeyframe& kf : model.keyframes) keyframe_by_id[kf.id] = &kf;
    fmt::memory_buffer b;
    double error_sum = 0;
    for (std::size_t n = 0; n < model.points.size(); ++n) {
      const SparsePoint& p = model.points[n];
      if (exported.count(p.id) == 0) continue;
      double error = 0;
      for (const auto& [kf_id, index] : p.observations) {
        const SparseKeyframe& kf = *keyframe_by_id.at(kf_id);
        const Eigen::Vector3d pc = kf.camera_from_world * p.position_world;
        const SparseKeypoint& kp = kf.keypoints[index];
        const double du = cam.fx * pc.x() / pc.z() + cam.cx - kp.u;
        const double dv = cam.fy * pc.y() / pc.z() + cam.cy - kp.v;
        error += pc.z() > 0 ? std::hypot(du, dv) : 1e3;
      }
      error /= static_cast<double>(p.observations.size());
      error_sum += error;
      const Rgb c = point_colours.empty() ? Rgb{128, 128, 128} : point_colours[n];
      fmt::format_to(std::back_inserter(b), "{} {:.9f} {:.9f} {:.9f} {} {} {} {:.6f}", p.id + 1,
                     p.position_world.x(), p.position_world.y(), p.position_world.z(), c[0], c[1],
                     c[2], error);
      for (const auto& [kf_id, index] : p.observations) {
        fmt::format_to(std::back_inserter(b), " {} {}", image_id.at(kf_id), index);
      }
      b.push_back('\n');
    }
    stats.points = static_cast<int>(exported.size());
    stats.images = static_cast<int>(model.keyframes.size());
    stats.mean_track_length =
        stats.points > 0 ? static_cast<double>(stats.observations) / stats.points : 0.0;
    stats.mean_reprojection_error_px = stats.points > 0 ? error_sum / stats.points : 0.0;
    OutputFile output(sparse_dir / "points3D.txt");
    std::ostream& out = output.stream();
    out << "# 3D point list with one line of data per point:\n"
        << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
        << fmt::format("# Number of points: {}, mean track length: {:.6g}\n", stats.points,
                       stats.mean_track_length);
    out.write(b.data(), static_cast<std::streamsize>(b.size()));
    output.Commit();
  }
  return stats;
}

ColmapExportStats ExportColmap(const SparseModel& model, const KeyframeImageSource& source,
                               const ColmapExportOptions& options, const fs::path& out_dir) {
  options.Check();
  const CameraModel pinhole = source.PinholeCamera();
  const SparseCamera& c = model.camera;
  const auto differs = [](double a, double b) {
    return std::abs(a - b) > 1e-6 * std::abs(b) + 1e-9;
  };
  if (c.width != pinhole.width() || c.height != pinhole.height() || differs(c.fx, pinhole.fx()) ||
      differs(c.fy, pinhole.fy()) || differs(c.cx, pinhole.cx()) || differs(c.cy, pinhole.cy())) {
    throw OptionError(fmt::format(
        "the run's camera ({}x{} fx {:.3f} cx {:.3f}) differs from the dataset's settings "
        "({}x{} fx {:.3f} cx {:.3f}); pass the --settings the run used",
        c.width, c.height, c.fx, c.cx, pinhole.width(), pinhole.height(), pinhole.fx(),
        pinhole.cx()));
  }
  const fs::path images_dir = out_dir / "images";
  fs::create_directories(images_dir);
  std::unordered_map<std::int64_t, std::size_t> point_index;
  for (std::size_t n = 0; n < model.points.size(); ++n) point_index[model.points[n].id] = n;
  std::vector<std::array<double, 4>> colour_sums(model.points.size(), {0, 0, 0, 0});
  std::vector<std::string> names;
  Progress progress("export-colmap", model.keyframes.size(), options.quiet);
  for (const SparseKeyframe& kf : model.keyframes) {
    const auto frame = source.FindFrame(kf.t_ns);
    if (!frame) {
      throw InputError(model.source,
                       fmt::format("keyframe {} at {:.9f} s has no dataset frame with that "
                                   "timestamp (another dataset?)",
                                   kf.id, static_cast<double>(kf.t_ns) * 1e-9));
    }
    const KeyframeImages images = source.Load(*frame);
    // Images as tracked: rectified left (already ideal) or the undistorted colour image.
    const cv::Mat image = images.colour.empty() ? UndistortImage(images.grey, source.camera())
                                                : UndistortImage(images.colour, source.camera());
    names.push_back(fmt::format("{}.png", kf.t_ns));
    if (options.write_images && !cv::imwrite((images_dir / names.back()).string(), image)) {
      throw Error(fmt::format("cannot write {}", (images_dir / names.back()).string()));
    }
    for (const SparseKeypoint& kp : kf.keypoints) {
      if (kp.point_id < 0) continue;
      const auto it = point_index.find(kp.point_id);
      if (it == point_index.end()) continue;
      const int u = static_cast<int>(std::lround(kp.u)), v = static_cast<int>(std::lround(kp.v));
      if (u < 0 || v < 0 || u >= image.cols || v >= image.rows) continue;
      auto& sum = colour_sums[it->second];
      if (image.channels() == 3) {
        const cv::Vec3b bgr = image.at<cv::Vec3b>(v, u);
        sum[0] += bgr[2];
        sum[1] += bgr[1];
        sum[2] += bgr[0];
      } else {
        const double g = image.at<std::uint8_t>(v, u);
        sum[0] += g;
        sum[1] += g;
        sum[2] += g;
      }
      sum[3] += 1;
    }
    progress.Add();
  }
  progress.Finish();
  std::vector<Rgb> colours(model.points.size(), Rgb{128, 128, 128});
  for (std::size_t n = 0; n < colours.size(); ++n) {
    const auto& s = colour_sums[n];
    if (s[3] > 0) {
      for (int a = 0; a < 3; ++a)
        colours[n][a] = static_cast<std::uint8_t>(std::lround(s[a] / s[3]));
    }
  }
  return WriteColmapText(model, names, colours, options, out_dir / "sparse");
}

}  // namespace pkslam::dense
