#include "system/estimate_health.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace pkslam {

std::vector<double> LostForGoodTimes(const std::vector<FrameRecord>& records) {
  std::vector<double> out;
  for (std::size_t i = 1; i < records.size(); ++i) {
    const TrackingState before = records[i - 1].state;
    const TrackingState now = records[i].state;
    const bool was_tracking =
        before == TrackingState::kOk || before == TrackingState::kRecentlyLost;
    const bool gave_up = now == TrackingState::kLost || now == TrackingState::kNotInitialized;
    if (was_tracking && gave_up) out.push_back(static_cast<double>(records[i].t_ns) * 1e-9);
  }
  return out;
}

EstimateHealth AssessEstimate(const std::vector<double>& lost_for_good_s,
                              const std::vector<LoopEvent>& merges, int maps_at_end) {
  EstimateHealth h;
  h.lost_for_good_s = lost_for_good_s;
  h.maps_at_end = maps_at_end;
  for (const LoopEvent& m : merges) {
    h.largest_merge_correction_m = std::max(h.largest_merge_correction_m, m.correction_m);
  }
  for (std::size_t k = 0; k < lost_for_good_s.size() && k < kMaxLossWarnings; ++k) {
    const double t = lost_for_good_s[k];
    const double next = k + 1 < lost_for_good_s.size() ? lost_for_good_s[k + 1] : 1e300;
    // The first merge after this loss (and before the next) is the one that joined the map
    // started here back to an earlier one.
    const auto merge = std::find_if(merges.begin(), merges.end(), [&](const LoopEvent& m) {
      const double tm = static_cast<double>(m.t_ns) * 1e-9;
      return tm > t && tm < next;
    });
    std::string text = fmt::format("tracking lost for good at t = {:.3f} s: ", t);
    text +=
        merge == merges.end()
            ? std::string("the trajectory continues in a new (or reset) map")
            : fmt::format("the new map was merged back at t = {:.3f} s, moving a keyframe {:.2f} m",
                          static_cast<double>(merge->t_ns) * 1e-9, merge->correction_m);
    h.warnings.push_back(std::move(text));
  }
  if (lost_for_good_s.size() > kMaxLossWarnings) {
    h.warnings.push_back(fmt::format("tracking lost for good {} more times",
                                     lost_for_good_s.size() - kMaxLossWarnings));
  }
  if (maps_at_end > 1) {
    h.warnings.push_back(
        fmt::format("{} maps at the end were never merged: their poses are in frames of their own",
                    maps_at_end));
  }
  return h;
}

std::vector<LocalisationGap> LocalisationGaps(const std::vector<FrameRecord>& records) {
  std::vector<LocalisationGap> gaps;
  bool in_gap = false;
  for (const FrameRecord& r : records) {
    const double t = static_cast<double>(r.t_ns) * 1e-9;
    const bool tracked = r.state == TrackingState::kOk;
    if (!tracked && !in_gap) {
      gaps.push_back({t, std::nullopt, 0});
      in_gap = true;
    }
    if (!tracked) ++gaps.back().frames;
    if (tracked && in_gap) {
      gaps.back().relocalised_s = t;
      in_gap = false;
    }
  }
  return gaps;
}

std::string NoEstimateReason(int frames, int poses, bool never_initialised, bool monocular) {
  if (frames <= 0) return "no frame was read";
  const int needed = frames < 20 ? std::min(frames, 3)
                                 : std::max(3, static_cast<int>(std::ceil(0.1 * frames)));
  if (poses >= needed) return "";
  std::string why =
      never_initialised
          ? monocular ? "the map never initialised (a monocular map needs two views with enough "
                        "parallax and matches: move the camera sideways, or check the settings' "
                        "intrinsics)"
                      : "the map never initialised (a first frame needs 50 keypoints with a "
                        "stereo or depth measurement: check the calibration and the images)"
          : "tracking was lost for most of the run";
  return fmt::format("only {} of {} frames have a pose (at least {} needed): {}", poses, frames,
                     needed, why);
}

}  // namespace pkslam
