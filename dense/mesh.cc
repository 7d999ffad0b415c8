#include "dense/mesh.h"

#include <fmt/format.h>
#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/TriangleMeshIO.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

#include "core/util/cpu_time.h"
#include "core/util/error.h"
#include "core/util/progress.h"

namespace pkslam::dense {

namespace fs = std::filesystem;

void MeshOptions::Check() const {
  PKSLAM_CHECK_OPTION(voxel_m > 0 && voxel_m < 1, "--mesh-voxel", "{}", voxel_m);
  PKSLAM_CHECK_OPTION(truncation_m >= voxel_m, "--mesh-truncation", "{} (>= voxel {})",
                      truncation_m, voxel_m);
  depth.Check();
}

namespace {

// An Open3D image of `mat` (CV_32FC1 depth in metres, or CV_8UC3 RGB).
open3d::geometry::Image ToOpen3d(const cv::Mat& mat) {
  open3d::geometry::Image image;
  const int bytes = mat.depth() == CV_32F ? 4 : 1;
  image.Prepare(mat.cols, mat.rows, mat.channels(), bytes);
  const std::size_t row = static_cast<std::size_t>(mat.cols) * mat.channels() * bytes;
  for (int r = 0; r < mat.rows; ++r) {
    std::memcpy(image.data_.data() + static_cast<std::size_t>(r) * row, mat.ptr(r), row);
  }
  return image;
}

// The TSDF volume and what it fuses: depth maps of `camera`'s pixels (ideal pinhole).
class TsdfFusion {
 public:
  TsdfFusion(const MeshOptions& options, const CameraModel& camera)
      : intrinsic_(camera.width(), camera.height(), camera.fx(), camera.fy(), camera.cx(),
                   camera.cy()),
        max_depth_(options.depth.MaxDepth()),
        volume_(options.voxel_m, options.truncation_m,
                open3d::pipelines::integration::TSDFVolumeColorType::RGB8) {}

  void Integrate(const cv::Mat& depth_m, const cv::Mat& grey, const cv::Mat& colour_bgr,
                 const SE3d& world_from_camera) {
    cv::Mat rgb;
    if (!colour_bgr.empty()) {
      cv::cvtColor(colour_bgr, rgb, cv::COLOR_BGR2RGB);
    } else {
      cv::cvtColor(grey, rgb, cv::COLOR_GRAY2RGB);
    }
    const auto rgbd = open3d::geometry::RGBDImage::CreateFromColorAndDepth(
        ToOpen3d(rgb), ToOpen3d(depth_m), 1.0, max_depth_, false);
    volume_.Integrate(*rgbd, intrinsic_, world_from_camera.Inverse().Matrix());
    ++integrated_;
  }

  // Extracts the mesh and writes it; fills the mesh counts of *stats.
  void Write(const fs::path& file, MeshStats* stats) {
    const auto mesh = volume_.ExtractTriangleMesh();
    stats->vertices = mesh->vertices_.size();
    stats->triangles = mesh->triangles_.size();
    if (stats->triangles == 0) throw Error("the TSDF mesh is empty (no depth was fused)");
    mesh->ComputeVertexNormals();
    if (!open3d::io::WriteTriangleMesh(file.string(), *mesh, /*write_ascii=*/false,
                                       /*compressed=*/false, /*write_vertex_normals=*/true,
                                       /*write_vertex_colors=*/true,
                                       /*write_triangle_uvs=*/false,
                                       /*print_progress=*/false)) {
      throw OutputError(file, "Open3D could not write the mesh");
    }
    stats->peak_memory_mib = PeakMemoryMiB();
  }

  int integrated() const { return integrated_; }

 private:
  open3d::camera::PinholeCameraIntrinsic intrinsic_;
  double max_depth_;
  open3d::pipelines::integration::ScalableTSDFVolume volume_;
  int integrated_ = 0;
};

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

MeshStats BuildTsdfMesh(const Trajectory& keyframes, const KeyframeImageSource& source,
                        const MeshOptions& options, const fs::path& file) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  MeshStats stats;
  stats.keyframes = static_cast<int>(keyframes.size());
  struct Job {
    std::size_t frame;
    SE3d world_from_camera;
  };
  std::vector<Job> jobs;
  for (const StampedPose& kf : keyframes.poses) {
    if (const auto frame = source.FindFrame(kf.t_ns)) jobs.push_back({*frame, kf.pose});
  }
  stats.keyframes_used = static_cast<int>(jobs.size());
  if (jobs.empty()) {
    throw InputError(keyframes.source,
                     "no keyframe timestamp matches a frame of the dataset (another dataset?)");
  }
  // The pixels are the depth map's camera: the rectified pinhole for stereo (RGB-D: camera1's
  // pinhole part; its distortion, small on TUM, is ignored here).
  TsdfFusion fusion(options, source.camera());
  Progress progress("mesh", jobs.size(), options.depth.quiet);
  const std::size_t batch = static_cast<std::size_t>(std::max(1, options.depth.batch));
  for (std::size_t begin = 0; begin < jobs.size(); begin += batch) {
    const std::size_t end = std::min(jobs.size(), begin + batch);
    std::vector<KeyframeImages> images(end - begin);
    std::vector<cv::Mat> depth(end - begin);
    tbb::parallel_for(begin, end, [&](std::size_t j) {
      images[j - begin] = source.Load(jobs[j].frame);
      depth[j - begin] =
          KeyframeDepth(images[j - begin], source, options.depth, options.depth.MaxDepth());
    });
    for (std::size_t j = begin; j < end; ++j) {
      fusion.Integrate(depth[j - begin], images[j - begin].grey, images[j - begin].colour,
                       jobs[j].world_from_camera);
      progress.Add();
    }
  }
  progress.Finish();
  fusion.Write(file, &stats);
  stats.seconds = SecondsSince(start);
  return stats;
}

MeshStats BuildFilteredTsdfMesh(const Trajectory& keyframes, const KeyframeImageSource& source,
                                const MeshOptions& options, const fs::path& file, PointCloud* cloud,
                                DenseStats* cloud_stats) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  TsdfFusion fusion(options, source.camera());
  *cloud = BuildDenseCloud(keyframes, source, options.depth, cloud_stats,
                           [&](const cv::Mat& depth, const cv::Mat& grey, const cv::Mat& colour,
                               const SE3d& world_from_camera) {
                             fusion.Integrate(depth, grey, colour, world_from_camera);
                           });
  MeshStats stats;
  stats.keyframes = cloud_stats->keyframes;
  stats.keyframes_used = fusion.integrated();
  fusion.Write(file, &stats);
  stats.seconds = SecondsSince(start);
  return stats;
}

bool PlyHasFaces(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("end_header", 0) == 0) return false;
    unsigned long long faces = 0;
    if (std::sscanf(line.c_str(), "element face %llu", &faces) == 1) return faces > 0;
  }
  return false;
}

PointCloud SampleMesh(const fs::path& file, double spacing_m) {
  PKSLAM_CHECK_OPTION(spacing_m > 0, "--mesh-spacing", "{}", spacing_m);
  open3d::geometry::TriangleMesh mesh;
  if (!open3d::io::ReadTriangleMesh(file.string(), mesh) || mesh.triangles_.empty()) {
    throw InputError(file, "not a readable triangle mesh");
  }
  const double area = mesh.GetSurfaceArea();
  const auto n = static_cast<std::size_t>(std::max(1.0, area / (spacing_m * spacing_m)));
  const auto sampled = mesh.SamplePointsUniformly(n, false);
  PointCloud cloud;
  cloud.points.reserve(sampled->points_.size());
  for (const auto& p : sampled->points_) cloud.points.push_back(p.cast<float>());
  if (sampled->HasColors()) {
    for (const auto& c : sampled->colors_) {
      cloud.colours.push_back({static_cast<std::uint8_t>(std::lround(255 * c.x())),
                               static_cast<std::uint8_t>(std::lround(255 * c.y())),
                               static_cast<std::uint8_t>(std::lround(255 * c.z()))});
    }
  }
  return cloud;
}

}  // namespace pkslam::dense
