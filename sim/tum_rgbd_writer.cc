#include "sim/tum_rgbd_writer.h"

#include <fmt/format.h>

#include <opencv2/imgproc.hpp>

#include "core/util/error.h"
#include "sim/euroc_writer.h"

namespace pkslam::sim {

std::string TumTimestamp(std::int64_t t_ns) {
  PKSLAM_CHECK(t_ns >= 0 && t_ns % 1000 == 0, "TUM timestamp {} ns is not whole microseconds",
               t_ns);
  return fmt::format("{}.{:06d}", t_ns / 1'000'000'000, (t_ns % 1'000'000'000) / 1000);
}

namespace {

std::ofstream Open(const std::filesystem::path& file, const std::string& header) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(fmt::format("cannot write {}", file.string()));
  out << header;
  return out;
}

}  // namespace

TumRgbdWriter::TumRgbdWriter(const std::filesystem::path& dir) : dir_(dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir / "rgb", ec);
  std::filesystem::create_directories(dir / "depth", ec);
  if (ec) throw Error(fmt::format("cannot create {}: {}", dir.string(), ec.message()));
  rgb_txt_ =
      Open(dir / "rgb.txt", "# color images\n# file: 'pkslam simulate'\n# timestamp filename\n");
  depth_txt_ =
      Open(dir / "depth.txt", "# depth maps\n# file: 'pkslam simulate'\n# timestamp filename\n");
  assoc_txt_ = Open(dir / "associations.txt", "");
  gt_txt_ = Open(dir / "groundtruth.txt",
                 "# ground truth trajectory\n# file: 'pkslam simulate'\n"
                 "# timestamp tx ty tz qx qy qz qw\n");
}

void TumRgbdWriter::WriteFrame(std::int64_t t_ns, const cv::Mat& colour_rgb, const cv::Mat& depth) {
  const auto [colour_file, depth_file] = AddFrame(t_ns);
  WriteImages(colour_file, depth_file, colour_rgb, depth);
}

std::pair<std::filesystem::path, std::filesystem::path> TumRgbdWriter::AddFrame(std::int64_t t_ns) {
  const std::string ts = TumTimestamp(t_ns);
  rgb_txt_ << ts << " rgb/" << ts << ".png\n";
  depth_txt_ << ts << " depth/" << ts << ".png\n";
  assoc_txt_ << ts << " rgb/" << ts << ".png " << ts << " depth/" << ts << ".png\n";
  return {dir_ / "rgb" / (ts + ".png"), dir_ / "depth" / (ts + ".png")};
}

void TumRgbdWriter::WriteImages(const std::filesystem::path& colour_file,
                                const std::filesystem::path& depth_file, const cv::Mat& colour_rgb,
                                const cv::Mat& depth) {
  PKSLAM_CHECK(colour_rgb.type() == CV_8UC3 && depth.type() == CV_16U, "bad RGB-D image types");
  cv::Mat bgr;
  cv::cvtColor(colour_rgb, bgr, cv::COLOR_RGB2BGR);
  WritePng(colour_file, bgr);
  WritePng(depth_file, depth);
}

void TumRgbdWriter::WriteGroundTruth(std::int64_t t_ns, const SE3d& world_from_camera) {
  const Eigen::Vector3d& p = world_from_camera.translation();
  const Eigen::Quaterniond& q = world_from_camera.quaternion();
  gt_txt_ << fmt::format("{} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n",
                         TumTimestamp(t_ns), p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
}

void TumRgbdWriter::Close() {
  if (closed_) return;
  closed_ = true;
  rgb_txt_.close();
  depth_txt_.close();
  assoc_txt_.close();
  gt_txt_.close();
  if (rgb_txt_.fail() || depth_txt_.fail() || assoc_txt_.fail() || gt_txt_.fail()) {
    throw Error(fmt::format("writing the TUM RGB-D files under {} failed", dir_.string()));
  }
}

TumRgbdWriter::~TumRgbdWriter() {
  try {
    Close();
  } catch (const Error&) {
    // Destructors must not throw; callers that care call Close().
  }
}

}  // namespace pkslam::sim
