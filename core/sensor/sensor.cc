#include "core/sensor/sensor.h"

#include <array>
#include <utility>

namespace pkslam {
namespace {

constexpr std::array<std::pair<Sensor, std::string_view>, 6> kNames{{
    {Sensor::kMonocular, "mono"},
    {Sensor::kStereo, "stereo"},
    {Sensor::kRgbd, "rgbd"},
    {Sensor::kMonocularInertial, "mono-inertial"},
    {Sensor::kStereoInertial, "stereo-inertial"},
    {Sensor::kRgbdInertial, "rgbd-inertial"},
}};

}  // namespace

std::string_view SensorName(Sensor s) {
  for (const auto& [sensor, name] : kNames) {
    if (sensor == s) return name;
  }
  return "unknown";
}

std::optional<Sensor> ParseSensor(std::string_view name) {
  for (const auto& [sensor, n] : kNames) {
    if (n == name) return sensor;
  }
  return std::nullopt;
}

}  // namespace pkslam
