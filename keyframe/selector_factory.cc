#include "keyframe/selector_factory.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/util/error.h"
#include "keyframe/baseline_selectors.h"
#include "keyframe/orbslam3_selector.h"
#include "keyframe/pks_released_selector.h"
#include "keyframe/pks_selector.h"
#include "keyframe/vins_parallax_selector.h"

namespace pkslam {
namespace {

// Reads parameters into an options struct, rejecting names the selector does not have.
class ParameterReader {
 public:
  ParameterReader(std::string selector, const std::map<std::string, double>& parameters)
      : selector_(std::move(selector)), parameters_(parameters) {}

  void Read(const std::string& name, double* value) {
    known_.push_back(name);
    if (auto it = parameters_.find(name); it != parameters_.end()) *value = it->second;
  }
  void Read(const std::string& name, int* value) {
    double v = *value;
    Read(name, &v);
    *value = static_cast<int>(v);
  }
  void Read(const std::string& name, bool* value) {
    double v = *value ? 1.0 : 0.0;
    Read(name, &v);
    if (v != 0.0 && v != 1.0) {
      throw OptionError(fmt::format("selector '{}': parameter '{}' is a switch (0 or 1), not {}",
                                    selector_, name, v));
    }
    *value = v == 1.0;
  }
  void RejectUnknown() const {
    for (const auto& [name, value] : parameters_) {
      if (std::find(known_.begin(), known_.end(), name) == known_.end()) {
        throw OptionError(fmt::format("selector '{}' has no parameter '{}' (known: {})", selector_,
                                      name, fmt::join(known_, ", ")));
      }
    }
  }

 private:
  std::string selector_;
  const std::map<std::string, double>& parameters_;
  std::vector<std::string> known_;
};

}  // namespace

std::vector<std::string> KeyframeSelectorNames() {
  return {"orbslam3", "pks", "pks-released", "interval", "ptam", "match-count", "vins-parallax"};
}

std::unique_ptr<KeyframeSelector> MakeKeyframeSelector(
    const std::string& name, const std::map<std::string, double>& parameters) {
  ParameterReader reader(name, parameters);
  if (name == "orbslam3") {
    OrbSlam3SelectorOptions o;
    reader.Read("min_frames", &o.min_frames);
    reader.Read("max_frames", &o.max_frames);
    reader.Read("imu_uninitialised_interval", &o.imu_uninitialised_interval_s);
    reader.Read("inertial_interval", &o.inertial_interval_s);
    reader.Read("close_tracked_max", &o.close_tracked_max);
    reader.Read("close_untracked_min", &o.close_untracked_min);
    reader.Read("no_keyframe_while_imu_initialises", &o.no_keyframe_while_imu_initialises);
    reader.RejectUnknown();
    return std::make_unique<OrbSlam3Selector>(o);
  }
  if (name == "pks" || name == "pks-released") {
    PksOptions o;
    reader.Read("region_width", &o.region_width_deg);
    reader.Read("regions", &o.regions);
    reader.Read("delta", &o.delta_deg);
    reader.Read("visual_interval", &o.visual_interval_s);
    reader.Read("grid", &o.grid);
    reader.Read("normal_neighbours", &o.normal_neighbours);
    reader.Read("imu_threshold", &o.imu_threshold);
    reader.Read("min_translation", &o.min_translation_m);
    reader.Read("imu_uninitialised_interval", &o.imu_uninitialised_interval_s);
    reader.Read("inertial_interval", &o.inertial_interval_s);
    reader.Read("close_tracked_max", &o.close_tracked_max);
    reader.Read("close_untracked_min", &o.close_untracked_min);
    reader.Read("weak_tracking_ratio", &o.weak_tracking_ratio);
    if (name == "pks") {
      reader.RejectUnknown();
      return std::make_unique<PksSelector>(o);
    }
    reader.Read("forced_interval", &o.forced_interval);
    reader.Read("late_denominator_after", &o.late_denominator_after);
    reader.Read("pairing_radius", &o.pairing_radius_px);
    reader.Read("pairing_max_hamming", &o.pairing_max_hamming);
    reader.Read("identity_pairing", &o.identity_pairing);
    reader.Read("frozen_normals", &o.frozen_normals);
    reader.Read("no_keyframe_while_imu_initialises", &o.no_keyframe_while_imu_initialises);
    reader.RejectUnknown();
    return std::make_unique<PksReleasedSelector>(o);
  }
  if (name == "vins-parallax") {
    VinsParallaxOptions o;
    reader.Read("parallax", &o.parallax_px);
    reader.Read("focal", &o.focal_px);
    reader.Read("min_tracked", &o.min_tracked);
    reader.Read("rotation_compensation", &o.rotation_compensation);
    reader.Read("imu_uninitialised_interval", &o.imu_uninitialised_interval_s);
    reader.RejectUnknown();
    return std::make_unique<VinsParallaxSelector>(o);
  }
  const std::map<std::string, BaselineKind> baselines = {
      {"interval", BaselineKind::kInterval},
      {"ptam", BaselineKind::kPtam},
      {"match-count", BaselineKind::kMatchCount}};
  if (auto it = baselines.find(name); it != baselines.end()) {
    BaselineOptions o;
    switch (it->second) {
      case BaselineKind::kInterval:
        reader.Read("frames", &o.interval_frames);
        reader.Read("seconds", &o.interval_seconds);
        break;
      case BaselineKind::kPtam:
        reader.Read("min_frames", &o.ptam_min_frames);
        reader.Read("min_distance_ratio", &o.ptam_min_distance_ratio);
        break;
      case BaselineKind::kMatchCount:
        reader.Read("min_matches", &o.match_count_min);
        break;
    }
    reader.Read("imu_uninitialised_interval", &o.imu_uninitialised_interval_s);
    reader.RejectUnknown();
    return std::make_unique<BaselineSelector>(it->second, o);
  }
  throw OptionError(fmt::format("unknown keyframe selector '{}' (known: {})", name,
                                fmt::join(KeyframeSelectorNames(), ", ")));
}

}  // namespace pkslam
