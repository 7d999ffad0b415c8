#include "dense/cloud_compare.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/geometry/point_cloud_index.h"
#include "core/util/error.h"

namespace pkslam::dense {

DistanceStats SummariseDistances(const std::vector<float>& distances,
                                 const std::vector<double>& thresholds_m) {
  DistanceStats s;
  s.thresholds_m = thresholds_m;
  s.within.assign(thresholds_m.size(), 0.0);
  s.count = distances.size();
  if (distances.empty()) return s;
  double sum = 0, sum_sq = 0;
  std::vector<std::size_t> counts(thresholds_m.size(), 0);
  for (float d : distances) {
    sum += d;
    sum_sq += static_cast<double>(d) * d;
    s.max = std::max(s.max, static_cast<double>(d));
    for (std::size_t t = 0; t < thresholds_m.size(); ++t) {
      if (d <= thresholds_m[t]) ++counts[t];
    }
  }
  const double n = static_cast<double>(distances.size());
  s.mean = sum / n;
  s.rms = std::sqrt(sum_sq / n);
  for (std::size_t t = 0; t < thresholds_m.size(); ++t) s.within[t] = counts[t] / n;
  std::vector<float> sorted = distances;
  const std::size_t mid = sorted.size() / 2;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(mid), sorted.end());
  if (sorted.size() % 2 == 1) {
    s.median = sorted[mid];
  } else {
    const float upper = sorted[mid];
    const float lower = *std::max_element(sorted.begin(), sorted.begin() + static_cast<long>(mid));
    s.median = 0.5 * (static_cast<double>(lower) + upper);
  }
  return s;
}

std::vector<float> NearestDistances(const std::vector<Eigen::Vector3f>& query,
                                    const std::vector<Eigen::Vector3f>& target,
                                    std::vector<std::uint32_t>* nearest) {
  PKSLAM_CHECK(!target.empty(), "nearest-neighbour search in an empty cloud");
  PKSLAM_CHECK(target.size() < INT32_MAX, "too many points");
  if (nearest != nullptr) nearest->assign(query.size(), 0);
  const PointCloudIndex index(target, 10);
  std::vector<float> distances(query.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, query.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const auto [nearest_index, d2] = index.Nearest(query[i]);
                        distances[i] = std::sqrt(d2);
                        if (nearest != nullptr) {
                          (*nearest)[i] = static_cast<std::uint32_t>(nearest_index);
                        }
                      }
                    });
  return distances;
}

std::vector<float> SurfaceDistances(const std::vector<Eigen::Vector3f>& query,
                                    const std::vector<Eigen::Vector3f>& target,
                                    const std::vector<Eigen::Vector3f>& target_normals,
                                    const std::vector<std::uint32_t>& nearest) {
  PKSLAM_CHECK(target_normals.size() == target.size() && nearest.size() == query.size(),
               "{} normals for {} points, {} indices for {} queries", target_normals.size(),
               target.size(), nearest.size(), query.size());
  std::vector<float> distances(query.size());
  for (std::size_t i = 0; i < query.size(); ++i) {
    const std::uint32_t q = nearest[i];
    PKSLAM_CHECK(q < target.size(), "index {} of {}", q, target.size());
    distances[i] = std::abs(target_normals[q].dot(query[i] - target[q]));
  }
  return distances;
}

void CompareOptions::Check() const {
  for (double t : thresholds_m) {
    PKSLAM_CHECK_OPTION(t > 0 && std::isfinite(t), "thresholds", "{}", t);
  }
  PKSLAM_CHECK_OPTION(completeness_m > 0 && std::isfinite(completeness_m), "--completeness", "{}",
                      completeness_m);
}

CompareResult CompareClouds(const std::vector<Eigen::Vector3f>& cloud,
                            const std::vector<Eigen::Vector3f>& reference,
                            const CompareOptions& options,
                            const std::vector<std::uint8_t>& ref_subset,
                            const std::vector<Eigen::Vector3f>& ref_normals) {
  options.Check();
  PKSLAM_CHECK(!cloud.empty() && !reference.empty(), "comparing an empty cloud");
  PKSLAM_CHECK(ref_subset.empty() || ref_subset.size() == reference.size(),
               "{} subset flags for {} reference points", ref_subset.size(), reference.size());
  CompareResult r;
  r.cloud_points = cloud.size();
  r.ref_points = reference.size();
  PKSLAM_CHECK(ref_normals.empty() || ref_normals.size() == reference.size(),
               "{} normals for {} reference points", ref_normals.size(), reference.size());
  std::vector<std::uint32_t> nearest;
  r.accuracy_distances = NearestDistances(cloud, reference, &nearest);
  r.accuracy = SummariseDistances(r.accuracy_distances, options.thresholds_m);
  if (!ref_normals.empty()) {
    r.surface_accuracy = SummariseDistances(
        SurfaceDistances(cloud, reference, ref_normals, nearest), options.thresholds_m);
  }
  r.completeness_distances = NearestDistances(reference, cloud);
  r.reference_to_cloud = SummariseDistances(r.completeness_distances, options.thresholds_m);
  std::size_t covered = 0, subset = 0, subset_covered = 0;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const bool near = r.completeness_distances[i] <= options.completeness_m;
    covered += near;
    if (!ref_subset.empty() && ref_subset[i] != 0) {
      ++subset;
      subset_covered += near;
    }
  }
  r.completeness = static_cast<double>(covered) / static_cast<double>(reference.size());
  if (!ref_subset.empty()) {
    r.subset_points = subset;
    r.subset_completeness =
        subset > 0 ? static_cast<double>(subset_covered) / static_cast<double>(subset) : 0.0;
  }
  return r;
}

double Completeness(const std::vector<Eigen::Vector3f>& cloud,
                    const std::vector<Eigen::Vector3f>& reference, double threshold_m) {
  PKSLAM_CHECK(!cloud.empty() && !reference.empty(), "completeness of an empty cloud");
  PKSLAM_CHECK(threshold_m > 0, "completeness threshold {}", threshold_m);
  const std::vector<float> d = NearestDistances(reference, cloud);
  const auto covered = std::count_if(d.begin(), d.end(), [&](float x) { return x <= threshold_m; });
  return static_cast<double>(covered) / static_cast<double>(reference.size());
}

void WriteDistanceStatsJson(const DistanceStats& stats, JsonWriter& json) {
  json.BeginObject();
  json.Member("count", static_cast<std::uint64_t>(stats.count));
  json.Member("mean", stats.mean);
  json.Member("median", stats.median);
  json.Member("rms", stats.rms);
  json.Member("max", stats.max);
  json.Key("within").BeginObject();
  for (std::size_t t = 0; t < stats.thresholds_m.size(); ++t) {
    json.Member(fmt::format("{:g}", stats.thresholds_m[t]), stats.within[t]);
  }
  json.EndObject();
  json.EndObject();
}

}  // namespace pkslam::dense
