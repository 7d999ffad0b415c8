#include "io/sparse_model.h"

#include <fmt/format.h>

#include <fstream>
#include <map>
#include <string>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/text_rows.h"

namespace pkslam {

namespace fs = std::filesystem;

// A failed cross-reference check: a plain message (the reader turns it into an InputError).
#define CONSISTENT(cond, ...)                           \
  do {                                                  \
    if (!(cond)) throw Error(fmt::format(__VA_ARGS__)); \
  } while (false)

void SparseModel::CheckConsistency() const {
  std::map<std::int64_t, const SparseKeyframe*> keyframe_by_id;
  for (const SparseKeyframe& kf : keyframes) {
    CONSISTENT(keyframe_by_id.emplace(kf.id, &kf).second, "duplicate keyframe id {}", kf.id);
  }
  std::map<std::int64_t, const SparsePoint*> point_by_id;
  for (const SparsePoint& p : points) {
    CONSISTENT(point_by_id.emplace(p.id, &p).second, "duplicate point id {}", p.id);
    for (const auto& [kf_id, index] : p.observations) {
      const auto it = keyframe_by_id.find(kf_id);
      CONSISTENT(it != keyframe_by_id.end(), "point {} observed by unknown keyframe {}", p.id,
                 kf_id);
      const auto& kps = it->second->keypoints;
      CONSISTENT(index >= 0 && index < static_cast<int>(kps.size()),
                 "point {}: keyframe {} has no keypoint {}", p.id, kf_id, index);
      CONSISTENT(kps[index].point_id == p.id, "point {}: keyframe {} keypoint {} names point {}",
                 p.id, kf_id, index, kps[index].point_id);
    }
  }
  for (const SparseKeyframe& kf : keyframes) {
    for (std::size_t i = 0; i < kf.keypoints.size(); ++i) {
      const std::int64_t id = kf.keypoints[i].point_id;
      if (id < 0) continue;
      const auto it = point_by_id.find(id);
      CONSISTENT(it != point_by_id.end(), "keyframe {} keypoint {} names unknown point {}", kf.id,
                 i, id);
      bool listed = false;
      for (const auto& obs : it->second->observations) {
        listed |= obs.first == kf.id && obs.second == static_cast<int>(i);
      }
      CONSISTENT(listed, "point {} lacks the observation keyframe {} keypoint {}", id, kf.id, i);
    }
  }
}

#undef CONSISTENT

void WriteSparseModel(const SparseModel& model, const fs::path& file) {
  fmt::memory_buffer b;
  auto app = std::back_inserter(b);
  fmt::format_to(app, "pkslam_sparse_model 1\n# camera W H fx fy cx cy bf\n");
  const SparseCamera& c = model.camera;
  fmt::format_to(app, "camera {} {} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g}\n", c.width, c.height, c.fx,
                 c.fy, c.cx, c.cy, c.bf);
  fmt::format_to(app,
                 "# keyframe ID T_NS tx ty tz qx qy qz qw (camera_from_world) K, then K lines "
                 "U V OCTAVE POINT_ID\nkeyframes {}\n",
                 model.keyframes.size());
  for (const SparseKeyframe& kf : model.keyframes) {
    const Eigen::Vector3d& t = kf.camera_from_world.translation();
    const Eigen::Quaterniond& q = kf.camera_from_world.quaternion();
    fmt::format_to(app, "keyframe {} {} {:.9f} {:.9f} {:.9f} {:.12f} {:.12f} {:.12f} {:.12f} {}\n",
                   kf.id, kf.t_ns, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w(),
                   kf.keypoints.size());
    for (const SparseKeypoint& k : kf.keypoints) {
      fmt::format_to(app, "{:.4f} {:.4f} {} {}\n", k.u, k.v, k.octave, k.point_id);
    }
  }
  fmt::format_to(app, "# point ID X Y Z N, then N pairs KEYFRAME_ID KEYPOINT_INDEX\npoints {}\n",
                 model.points.size());
  for (const SparsePoint& p : model.points) {
    fmt::format_to(app, "point {} {:.9f} {:.9f} {:.9f} {}", p.id, p.position_world.x(),
                   p.position_world.y(), p.position_world.z(), p.observations.size());
    for (const auto& [kf, index] : p.observations) fmt::format_to(app, " {} {}", kf, index);
    fmt::format_to(app, "\n");
  }
  WriteFileAtomically(file, std::string_view(b.data(), b.size()));
}

SparseModel ReadSparseModel(const fs::path& file) {
  if (!fs::is_regular_file(file)) throw InputError(file, "sparse model file does not exist");
  SparseModel model;
  model.source = file;
  enum class State { kMagic, kCamera, kKeyframeCount, kKeyframe, kKeypoint, kPointCount, kPoint };
  State state = State::kMagic;
  std::size_t keyframes_expected = 0, points_expected = 0, keypoints_left = 0;
  std::size_t last_line = 0;
  auto count_field = [&](std::string_view text, std::size_t line, std::string_view what) {
    const std::int64_t n = Int64Field(text, file, line, what);
    if (n < 0) throw InputError(file, line, fmt::format("negative {}", what));
    return static_cast<std::size_t>(n);
  };
  auto expect = [&](const TextRow& row, std::string_view key, std::size_t fields) {
    if (row.fields.empty() || row.fields[0] != key) {
      throw InputError(file, row.line, fmt::format("expected a '{}' line", key));
    }
    RequireFieldCount(row, fields, file, std::string(key) + " line");
  };
  auto after_keyframes = [&] {
    return keyframes_expected == model.keyframes.size() ? State::kPointCount : State::kKeyframe;
  };
  ForEachDataRow(file, FieldSeparator::kWhitespace, [&](const TextRow& row) {
    last_line = row.line;
    const auto d = [&](std::size_t i, std::string_view what) {
      return DoubleField(row.fields[i], file, row.line, what);
    };
    const auto i64 = [&](std::size_t i, std::string_view what) {
      return Int64Field(row.fields[i], file, row.line, what);
    };
    switch (state) {
      case State::kMagic:
        expect(row, "pkslam_sparse_model", 2);
        if (row.fields[1] != "1") throw InputError(file, row.line, "unsupported version");
        state = State::kCamera;
        break;
      case State::kCamera: {
        expect(row, "camera", 8);
        SparseCamera& c = model.camera;
        c.width = static_cast<int>(i64(1, "width"));
        c.height = static_cast<int>(i64(2, "height"));
        c.fx = d(3, "fx");
        c.fy = d(4, "fy");
        c.cx = d(5, "cx");
        c.cy = d(6, "cy");
        c.bf = d(7, "bf");
        if (c.width <= 0 || c.height <= 0 || c.fx <= 0 || c.fy <= 0 || c.bf < 0) {
          throw InputError(file, row.line, "invalid camera");
        }
        state = State::kKeyframeCount;
        break;
      }
      case State::kKeyframeCount:
        expect(row, "keyframes", 2);
        keyframes_expected = count_field(row.fields[1], row.line, "keyframe count");
        state = after_keyframes();
        break;
      case State::kKeyframe: {
        expect(row, "keyframe", 11);
        SparseKeyframe kf;
        kf.id = i64(1, "keyframe id");
        kf.t_ns = i64(2, "timestamp");
        if (!model.keyframes.empty() && kf.id <= model.keyframes.back().id) {
          throw InputError(file, row.line, "keyframe ids must increase");
        }
        const Eigen::Vector3d t(d(3, "tx"), d(4, "ty"), d(5, "tz"));
        const Eigen::Quaterniond q(d(9, "qw"), d(6, "qx"), d(7, "qy"), d(8, "qz"));
        if (std::abs(q.norm() - 1.0) > 1e-6)
          throw InputError(file, row.line, "quaternion not unit");
        kf.camera_from_world = SE3d(q, t);
        keypoints_left = count_field(row.fields[10], row.line, "keypoint count");
        kf.keypoints.reserve(keypoints_left);
        model.keyframes.push_back(std::move(kf));
        state = keypoints_left > 0 ? State::kKeypoint : after_keyframes();
        break;
      }
      case State::kKeypoint: {
        RequireFieldCount(row, 4, file, "keypoint line 'U V OCTAVE POINT_ID'");
        SparseKeypoint k;
        k.u = static_cast<float>(d(0, "u"));
        k.v = static_cast<float>(d(1, "v"));
        k.octave = static_cast<int>(i64(2, "octave"));
        k.point_id = i64(3, "point id");
        if (k.point_id < -1) throw InputError(file, row.line, "point id < -1");
        model.keyframes.back().keypoints.push_back(k);
        if (--keypoints_left == 0) state = after_keyframes();
        break;
      }
      case State::kPointCount:
        expect(row, "points", 2);
        points_expected = count_field(row.fields[1], row.line, "point count");
        state = State::kPoint;
        break;
      case State::kPoint: {
        if (model.points.size() == points_expected) {
          throw InputError(file, row.line, "more points than the count says");
        }
        if (row.fields.size() < 6 || row.fields[0] != "point") {
          throw InputError(file, row.line, "expected a 'point ID X Y Z N ...' line");
        }
        SparsePoint p;
        p.id = i64(1, "point id");
        if (!model.points.empty() && p.id <= model.points.back().id) {
          throw InputError(file, row.line, "point ids must increase");
        }
        p.position_world = Eigen::Vector3d(d(2, "x"), d(3, "y"), d(4, "z"));
        const std::int64_t n = i64(5, "observation count");
        if (n < 0 || row.fields.size() != 6 + 2 * static_cast<std::size_t>(n)) {
          throw InputError(file, row.line, "observation count does not match the line");
        }
        for (std::int64_t o = 0; o < n; ++o) {
          p.observations.emplace_back(i64(6 + 2 * o, "keyframe id"),
                                      static_cast<int>(i64(7 + 2 * o, "keypoint index")));
        }
        model.points.push_back(std::move(p));
        break;
      }
    }
  });
  const bool complete = (state == State::kPoint && model.points.size() == points_expected);
  if (!complete) throw InputError(file, last_line, "file ends early (truncated sparse model)");
  try {
    model.CheckConsistency();
  } catch (const Error& e) {
    throw InputError(file, fmt::format("inconsistent sparse model: {}", e.what()));
  }
  return model;
}

}  // namespace pkslam
