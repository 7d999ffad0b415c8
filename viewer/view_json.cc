// ViewDataJson (view_data.h): the page's PKSLAM_DATA. Flat number arrays keep a 60 s run small.
#include <cmath>

#include "core/util/json_writer.h"
#include "viewer/view_data.h"

namespace pkslam {

namespace {

void Vec3(JsonWriter& json, const Eigen::Vector3d& v) {
  json.BeginArray();
  for (int i = 0; i < 3; ++i) json.Value(std::round(v[i] * 1e4) / 1e4);
  json.EndArray();
}

// t, x, y, z, qx, qy, qz, qw, ate per pose.
void Poses(JsonWriter& json, std::string_view key, const std::vector<ViewPose>& poses) {
  json.Key(key).BeginArray();
  for (const ViewPose& p : poses) {
    const Eigen::Vector3d& t = p.world_from_camera.translation();
    const Eigen::Quaterniond& q = p.world_from_camera.quaternion();
    for (double v : {p.t_s, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w(), p.ate_m}) {
      json.Value(std::round(v * 1e5) / 1e5);
    }
  }
  json.EndArray();
}

void Keyframes(JsonWriter& json, const std::vector<ViewKeyframe>& keyframes) {
  json.Key("keyframes").BeginArray();
  for (const ViewKeyframe& k : keyframes) {
    json.BeginObject();
    json.Member("t", k.t_s);
    json.Key("p");
    Vec3(json, k.world_from_camera.translation());
    const Eigen::Quaterniond& q = k.world_from_camera.quaternion();
    json.Key("q").BeginArray().Value(q.x()).Value(q.y()).Value(q.z()).Value(q.w()).EndArray();
    json.Member("reason", k.reason);
    json.EndObject();
  }
  json.EndArray();
}

}  // namespace

std::string ViewDataJson(const ViewData& data) {
  JsonWriter json(0);
  json.BeginObject();
  json.Member("title", data.title);
  json.Member("selector", data.selector);
  json.Member("alignment", data.alignment);
  json.Member("ate_rmse_m", data.ate_rmse_m);
  json.Key("warnings").BeginArray();
  for (const std::string& w : data.warnings) json.Value(w);
  json.EndArray();
  Poses(json, "estimate", data.estimate);
  json.Key("ground_truth").BeginArray();
  for (const Eigen::Vector3d& p : data.ground_truth) {
    for (int i = 0; i < 3; ++i) json.Value(std::round(p[i] * 1e4) / 1e4);
  }
  json.EndArray();
  Keyframes(json, data.keyframes);
  auto points = [&](std::string_view key, const std::vector<Eigen::Vector3f>& pts) {
    json.Key(key).BeginArray();
    for (const Eigen::Vector3f& p : pts) {
      for (int i = 0; i < 3; ++i) json.Value(std::round(static_cast<double>(p[i]) * 1e3) / 1e3);
    }
    json.EndArray();
  };
  points("map_points", data.map_points);
  points("cloud", data.cloud);
  json.Key("cloud_colours").BeginArray();
  for (const auto& c : data.cloud_colours) {
    for (int i = 0; i < 3; ++i) json.Value(static_cast<int>(c[static_cast<std::size_t>(i)]));
  }
  json.EndArray();
  json.Key("calibration").BeginArray();
  for (const ViewCalibrationStep& s : data.calibration) {
    json.BeginObject();
    json.Member("t", s.t_s);
    json.Key("e").BeginObject();
    for (const auto& [k, v] : s.estimate) json.Member(k, v);
    json.EndObject();
    json.EndObject();
  }
  json.EndArray();
  json.Key("calibration_file").BeginObject();
  for (const auto& [k, v] : data.calibration_file) json.Member(k, v);
  json.EndObject();
  json.Key("timeline").BeginArray();
  for (const ViewTimelineRow& r : data.timeline) {
    json.BeginObject();
    json.Member("t", r.t_s).Member("frame", r.frame).Member("state", r.state);
    json.Member("tracked", r.tracked_points).Member("kf", r.keyframe);
    if (!r.decision_reason.empty()) json.Member("reason", r.decision_reason);
    if (!r.quantities.empty()) {
      json.Key("q").BeginObject();
      for (const auto& [k, v] : r.quantities) json.Member(k, v);
      json.EndObject();
    }
    json.EndObject();
  }
  json.EndArray();
  // Further runs and bare trajectories: label, "run" or "trajectory", alignment, ATE rmse,
  // poses as "estimate" above, and a run's keyframes.
  json.Key("tracks").BeginArray();
  for (const ViewTrack& t : data.tracks) {
    json.BeginObject();
    json.Member("label", t.label).Member("source", t.source).Member("alignment", t.alignment);
    json.Member("ate_rmse_m", t.ate_rmse_m);
    Poses(json, "estimate", t.estimate);
    Keyframes(json, t.keyframes);
    json.EndObject();
  }
  json.EndArray();
  json.EndObject();
  return json.str();
}

}  // namespace pkslam
