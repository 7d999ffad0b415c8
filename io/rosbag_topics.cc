// BagTopics and the options of the bag <-> EuRoC conversions (rosbag_euroc.h).
#include <fmt/format.h>

#include <array>
#include <utility>

#include "core/util/error.h"
#include "io/rosbag_euroc.h"

namespace pkslam {
namespace {

std::array<std::pair<std::string_view, std::string*>, 6> Named(BagTopics* t) {
  return {{{"cam0", &t->cam0},
           {"cam1", &t->cam1},
           {"imu", &t->imu},
           {"vicon", &t->vicon},
           {"leica", &t->leica},
           {"mocap", &t->mocap}}};
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

}  // namespace

void BagTopics::Check() const {
  BagTopics copy = *this;
  const auto named = Named(&copy);
  for (std::size_t i = 0; i < named.size(); ++i) {
    const auto& [name, topic] = named[i];
    if (topic->empty() || topic->front() != '/') {
      throw OptionError(fmt::format("--topics: {}='{}' is not a ROS topic (/name)", name, *topic));
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (*named[j].second == *topic) {
        throw OptionError(
            fmt::format("--topics: {} and {} are both {}", named[j].first, name, *topic));
      }
    }
  }
}

BagTopics ParseBagTopics(std::string_view spec) {
  BagTopics topics;
  const auto named = Named(&topics);
  while (!Trim(spec).empty()) {
    const std::size_t comma = spec.find(',');
    const std::string_view item = Trim(spec.substr(0, comma));
    spec = comma == std::string_view::npos ? std::string_view() : spec.substr(comma + 1);
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) {
      throw OptionError(fmt::format("--topics: '{}' is not STREAM=TOPIC", item));
    }
    const std::string_view name = Trim(item.substr(0, eq));
    bool known = false;
    for (const auto& [stream, topic] : named) {
      if (stream == name) {
        *topic = std::string(Trim(item.substr(eq + 1)));
        known = true;
      }
    }
    if (!known) {
      throw OptionError(fmt::format(
          "--topics: unknown stream '{}' (cam0, cam1, imu, vicon, leica, mocap)", name));
    }
  }
  topics.Check();
  return topics;
}

void BagToEurocOptions::Check() const {
  topics.Check();
  reader.Check();
  PKSLAM_CHECK_OPTION(png_compression >= 0 && png_compression <= 9, "png_compression", "{}",
                      png_compression);
  PKSLAM_CHECK_OPTION(image_format == "png" || image_format == "pgm", "image_format", "'{}'",
                      image_format);
  PKSLAM_CHECK_OPTION(!require_cam1 || write_cam1, "require_cam1", "cam1 required but not written");
  PKSLAM_CHECK_OPTION(!require_imu || write_imu, "require_imu", "imu required but not written");
}

void EurocToBagOptions::Check() const {
  topics.Check();
  writer.Check();
}

}  // namespace pkslam
