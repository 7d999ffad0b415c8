#include "io/rigid_transform_file.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <cmath>
#include <fstream>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/text_rows.h"

namespace pkslam {

void WriteRigidTransform(const SE3d& transform, const std::filesystem::path& file,
                         std::string_view comment) {
  std::string text = fmt::format("# {}\n", comment);
  const Eigen::Matrix4d m = transform.Matrix();
  for (int r = 0; r < 4; ++r) {
    text += fmt::format("{:.12f} {:.12f} {:.12f} {:.12f}\n", m(r, 0), m(r, 1), m(r, 2), m(r, 3));
  }
  WriteFileAtomically(file, text);
}

SE3d ReadRigidTransform(const std::filesystem::path& file) {
  Eigen::Matrix4d m;
  int rows = 0;
  std::size_t last_line = 0;
  ForEachDataRow(file, FieldSeparator::kWhitespace, [&](const TextRow& row) {
    last_line = row.line;
    if (rows == 4) throw InputError(file, row.line, "more than four matrix rows");
    if (row.fields.size() != 4) {
      throw InputError(file, row.line,
                       fmt::format("expected 4 numbers, found {} fields", row.fields.size()));
    }
    for (int c = 0; c < 4; ++c) {
      const auto v = ParseDouble(row.fields[c]);
      if (!v) throw InputError(file, row.line, fmt::format("'{}' is not a number", row.fields[c]));
      m(rows, c) = *v;
    }
    ++rows;
  });
  if (rows != 4) throw InputError(file, fmt::format("{} matrix rows, expected 4", rows));
  if (const auto problem = FindRigidTransformProblem(m)) {
    throw InputError(file, problem->in_last_row ? last_line : 0, problem->what);
  }
  return SE3d(SO3d::FitToMatrix(m.topLeftCorner<3, 3>()), m.topRightCorner<3, 1>());
}

std::optional<RigidTransformProblem> FindRigidTransformProblem(const Eigen::Matrix4d& m) {
  if (!m.allFinite()) return RigidTransformProblem{"not finite", false};
  if (!m.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1), 1e-9)) {
    return RigidTransformProblem{"last row is not 0 0 0 1", true};
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if (!(r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || r.determinant() < 0) {
    return RigidTransformProblem{"the upper-left 3x3 block is not a rotation", false};
  }
  return std::nullopt;
}

Trajectory ChangeSensorFrame(const Trajectory& world_from_a, const SE3d& a_from_b) {
  Trajectory out;
  out.poses = world_from_a.poses;
  out.source = world_from_a.source;
  for (StampedPose& p : out.poses) p.pose = p.pose * a_from_b;
  return out;
}

RunAndGroundTruth ReadRunAndGroundTruth(const std::filesystem::path& run_dir,
                                        const std::filesystem::path& gt_file,
                                        std::optional<bool> monocular) {
  namespace fs = std::filesystem;
  RunAndGroundTruth r;
  r.ground_truth = ReadTrajectory(gt_file);
  const bool body_gt = gt_file.filename() == "data.csv" ||
                       DetectTrajectoryFormat(gt_file) == TrajectoryFormat::kEuroc;
  const fs::path body = run_dir / "trajectory_body.txt";
  const fs::path extrinsic = run_dir / "body_from_camera.txt";
  const bool camera_poses =
      !body_gt || (monocular ? *monocular && fs::exists(extrinsic) : !fs::exists(body));
  r.estimate_file = camera_poses ? run_dir / "trajectory.txt" : body;
  if (body_gt && camera_poses && fs::exists(extrinsic)) {
    r.ground_truth = ChangeSensorFrame(r.ground_truth, ReadRigidTransform(extrinsic));
  }
  // Peers (ORB-SLAM3) can repeat a stamp; evo evaluates every such pose, so does pkslam.
  r.estimate =
      ReadTrajectory(r.estimate_file, TrajectoryFormat::kTum, DuplicateTimestamps::kKeepAll);
  return r;
}

}  // namespace pkslam
