#include "keyframe/selector_factory.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/util/error.h"
#include "keyframe/orbslam3_selector.h"

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
  void RejectUnknown() const {
    for (const auto& [name, value] : parameters_) {
      if (std::find(known_.begin(), known_.end(), name) == known_.end()) {
        throw OptionError(fmt::format("selector '{}' has no parameter '{}' (known: {})",
                                      selector_, name, fmt::join(known_, ", ")));
      }
    }
  }

 private:
  std::string selector_;
  const std::map<std::string, double>& parameters_;
  std::vector<std::string> known_;
};

}  // namespace

std::vector<std::string> KeyframeSelectorNames() { return {"orbslam3"}; }

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
    reader.RejectUnknown();
    return std::make_unique<OrbSlam3Selector>(o);
  }
  throw OptionError(fmt::format("unknown keyframe selector '{}' (known: {})", name,
                                fmt::join(KeyframeSelectorNames(), ", ")));
}

}  // namespace pkslam
