// The sensor configurations of ORB-SLAM3.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace pkslam {

enum class Sensor {
  kMonocular,
  kStereo,
  kRgbd,
  kMonocularInertial,
  kStereoInertial,
  kRgbdInertial,
};

constexpr bool IsInertial(Sensor s) {
  return s == Sensor::kMonocularInertial || s == Sensor::kStereoInertial ||
         s == Sensor::kRgbdInertial;
}
constexpr bool IsMonocular(Sensor s) {
  return s == Sensor::kMonocular || s == Sensor::kMonocularInertial;
}
constexpr bool IsStereo(Sensor s) { return s == Sensor::kStereo || s == Sensor::kStereoInertial; }
constexpr bool IsRgbd(Sensor s) { return s == Sensor::kRgbd || s == Sensor::kRgbdInertial; }

// "mono", "stereo", "rgbd", "mono-inertial", "stereo-inertial", "rgbd-inertial".
std::string_view SensorName(Sensor s);
std::optional<Sensor> ParseSensor(std::string_view name);

}  // namespace pkslam
