// `pkslam export-colmap`: a run's keyframes as a COLMAP text model, so COLMAP / OpenMVS /
// Metashape users can densify them:
//   OUT/images/<t_ns>.png       the keyframe images as tracked: rectified left (stereo) or
//                               undistorted colour (RGB-D), i.e. images of an ideal pinhole
//   OUT/sparse/cameras.txt      one PINHOLE camera (fx fy cx cy)
//   OUT/sparse/images.txt       per keyframe: cam_from_world (qw qx qy qz tx ty tz), camera,
//                               name; then its keypoints "x y POINT3D_ID" (-1: none)
//   OUT/sparse/points3D.txt     map points: id, xyz, colour (mean over the track's pixels),
//                               mean reprojection error (px), track (IMAGE_ID POINT2D_IDX)
// COLMAP puts the centre of the top-left pixel at (0.5, 0.5), pkslam (OpenCV) at (0, 0), so
// principal points and keypoints are shifted by +0.5 px. Image ids are 1.. in keyframe
// order; POINT3D_ID = map point id + 1. Points with fewer than min_track_length observations
// are left out (their keypoints get -1).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "dense/keyframe_images.h"
#include "io/point_cloud.h"
#include "io/sparse_model.h"

namespace pkslam::dense {

struct ColmapExportOptions {
  int min_track_length = 2;
  bool write_images = true;
  bool quiet = false;  // no progress bar

  void Check() const;
};

struct ColmapExportStats {
  int images = 0;
  int points = 0;
  int points_dropped = 0;  // shorter tracks than min_track_length
  std::size_t observations = 0;
  double mean_track_length = 0;
  double mean_reprojection_error_px = 0;
};

// Writes the three text files into `sparse_dir` (created). `image_names` has one name per
// keyframe; `point_colours` is empty (grey 128) or one per model point. The model must be
// consistent (SparseModel::CheckConsistency).
ColmapExportStats WriteColmapText(const SparseModel& model,
                                  const std::vector<std::string>& image_names,
                                  const std::vector<Rgb>& point_colours,
                                  const ColmapExportOptions& options,
                                  const std::filesystem::path& sparse_dir);

// The full export (images + text model). The model's camera must match the dataset's
// (the run used the same settings): throws OptionError otherwise; InputError when a keyframe
// has no dataset frame with its timestamp.
ColmapExportStats ExportColmap(const SparseModel& model, const KeyframeImageSource& source,
                               const ColmapExportOptions& options,
                               const std::filesystem::path& out_dir);

}  // namespace pkslam::dense
