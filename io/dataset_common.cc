#include "io/dataset_common.h"

#include <fmt/format.h>

#include <algorithm>
#include <opencv2/imgcodecs.hpp>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/quantile.h"

namespace pkslam {

namespace {

// t1 - t0 for t1 > t0, exact even where it exceeds int64 (timestamps near both ends of the
// range are legal input: the signed subtraction overflowed).
std::uint64_t Interval(std::int64_t t0, std::int64_t t1) {
  return static_cast<std::uint64_t>(t1) - static_cast<std::uint64_t>(t0);
}

// The median interval between consecutive stamps (the upper median of an even count); t_ns has at
// least two stamps.
double MedianIntervalNs(const std::vector<std::int64_t>& t_ns) {
  std::vector<double> dt(t_ns.size() - 1);
  for (std::size_t i = 1; i < t_ns.size(); ++i) {
    dt[i - 1] = static_cast<double>(Interval(t_ns[i - 1], t_ns[i]));
  }
  return *Quantile(std::move(dt), 0.5);
}

}  // namespace

std::vector<TimeGap> FindTimeGaps(const std::vector<std::int64_t>& t_ns, double nominal_period_ns,
                                  double max_periods) {
  std::vector<TimeGap> gaps;
  if (t_ns.size() < 2) return gaps;
  if (nominal_period_ns <= 0) {
    nominal_period_ns = MedianIntervalNs(t_ns);
    if (nominal_period_ns <= 0) return gaps;
  }
  for (std::size_t i = 1; i < t_ns.size(); ++i) {
    const double periods = static_cast<double>(Interval(t_ns[i - 1], t_ns[i])) / nominal_period_ns;
    if (periods > max_periods) gaps.push_back({t_ns[i - 1], t_ns[i], periods});
  }
  return gaps;
}

void CheckTimeBase(const std::vector<std::int64_t>& t_ns, double nominal_rate_hz,
                   std::string_view rate_source, const std::filesystem::path& file,
                   std::string_view what) {
  if (nominal_rate_hz <= 0 || t_ns.size() < 3) return;
  const double median_ns = MedianIntervalNs(t_ns);
  const double nominal_ns = 1e9 / nominal_rate_hz;
  const double ratio = nominal_ns / std::max(median_ns, 1.0);  // > 1: stamps too close
  if (ratio <= 5.0 && ratio >= 0.2) return;
  // The unit the stamps would be in if they were right (the ratio a power of 1000).
  std::string hint;
  for (const auto& [factor, unit] : {std::pair{1e3, "microseconds"}, std::pair{1e6, "milliseconds"},
                                     std::pair{1e9, "seconds"}}) {
    if (ratio > factor / 5.0 && ratio < factor * 5.0) {
      hint = fmt::format(": the stamps look like {}, where nanoseconds belong", unit);
    }
  }
  if (ratio < 1.0 && ratio > 1e-3 / 5.0 && ratio < 1e-3 * 5.0) {
    hint = ": the stamps look 1000x too large (picoseconds, or nanoseconds scaled twice?)";
  }
  throw InputError(file, fmt::format(
                             "{} {:.6g} ns apart (median), but {} says {} Hz ({:.6g} ns){}", what,
                             median_ns, rate_source, nominal_rate_hz, nominal_ns, hint));
}

double MeasuredRateHz(std::int64_t first_ns, std::int64_t last_ns, std::size_t count) {
  if (count < 2 || last_ns <= first_ns) return 0.0;
  return static_cast<double>(count - 1) * 1e9 / static_cast<double>(last_ns - first_ns);
}

void FillImageStream(const std::vector<ImageEntry>& listed, double frame_gap_periods,
                     ImageStream* stream) {
  stream->listed = listed.size();
  stream->images.clear();
  stream->missing.clear();
  for (const ImageEntry& entry : listed) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(entry.path, ec)) {
      stream->images.push_back(entry);
    } else {
      stream->missing.push_back(entry.path);
    }
  }
  if (!stream->missing.empty()) {
    std::string first;
    const std::size_t shown = std::min<std::size_t>(stream->missing.size(), 3);
    for (std::size_t i = 0; i < shown; ++i) {
      first += (i ? ", " : "") + stream->missing[i].filename().string();
    }
    PKSLAM_LOG_WARN("{}: {} of {} images listed in {} are missing and skipped (first: {}{})",
                    stream->name, stream->missing.size(), stream->listed,
                    stream->list_file.string(), first,
                    stream->missing.size() > shown ? ", ..." : "");
  }
  std::vector<std::int64_t> t_ns;
  t_ns.reserve(stream->images.size());
  for (const ImageEntry& entry : stream->images) t_ns.push_back(entry.t_ns);
  const std::string rate_source = stream->name == "rgb" || stream->name == "depth"
                                      ? std::string("TUM RGB-D's nominal rate")
                                      : stream->name + "/sensor.yaml";
  CheckTimeBase(t_ns, stream->nominal_rate_hz, rate_source, stream->list_file, "images are");
  const double period_ns = stream->nominal_rate_hz > 0 ? 1e9 / stream->nominal_rate_hz : 0.0;
  stream->gaps = FindTimeGaps(t_ns, period_ns, frame_gap_periods);
}

namespace {

cv::Mat LoadImage(const std::filesystem::path& path, int flags) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "image file not found");
  cv::Mat image = cv::imread(path.string(), flags);
  if (image.empty()) throw InputError(path, "cannot decode image (corrupt or unsupported)");
  return image;
}

}  // namespace

cv::Mat LoadGreyImage(const std::filesystem::path& path) {
  cv::Mat grey = LoadImage(path, cv::IMREAD_GRAYSCALE);
  // OpenCV reads a 16-bit image as 8-bit by dropping its low byte: one that holds 8-bit
  // (0-255) or 12-bit values comes out black or nearly so, and tracking silently found no
  // features. Such frames are recognised (the check costs a look only at dark frames).
  double max_grey = 0;
  cv::minMaxLoc(grey, nullptr, &max_grey);
  if (max_grey < 16) {
    const cv::Mat raw = LoadImage(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE);
    double max_raw = 0;
    cv::minMaxLoc(raw, nullptr, &max_raw);
    if (raw.depth() == CV_16U && max_raw > 0) {
      throw InputError(path, fmt::format("16-bit image whose values reach only {} (8- or 12-bit "
                                         "data): pkslam reads 16-bit images as full-range and "
                                         "it would be black; save the images as 8-bit",
                                         max_raw));
    }
  }
  return grey;
}

cv::Mat LoadColourImage(const std::filesystem::path& path) {
  return LoadImage(path, cv::IMREAD_COLOR);
}

cv::Mat LoadUnchangedImage(const std::filesystem::path& path) {
  return LoadImage(path, cv::IMREAD_UNCHANGED);
}

}  // namespace pkslam
