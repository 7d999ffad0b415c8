// Comparing a reconstructed cloud with a reference cloud by nearest-neighbour distances
// (k-d tree: core/geometry/point_cloud_index.h):
//   accuracy      distances cloud -> reference: mean, median, RMS, max, share within
//                 1 / 2 / 5 cm; with reference normals also the distance to the reference
//                 surface (|n . (p - q)| at the nearest reference point q: a point sampled
//                 every s metres puts an exact surface point up to s / sqrt(2) from the
//                 nearest sample, which the nearest-neighbour distance counts as error);
//   completeness  distances reference -> cloud: the share of reference points with a cloud
//                 point within 5 cm (optionally only over a subset of the reference, e.g.
//                 the part the keyframes saw: dense/visibility.h).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/util/json_writer.h"

namespace pkslam::dense {

struct DistanceStats {
  std::size_t count = 0;
  double mean = 0, median = 0, rms = 0, max = 0;
  std::vector<double> thresholds_m;  // as given
  std::vector<double> within;        // share of distances <= each threshold
};

// Statistics of a set of distances (empty set: count 0, zeros).
DistanceStats SummariseDistances(const std::vector<float>& distances,
                                 const std::vector<double>& thresholds_m);

// For each query point, the Euclidean distance to its nearest point of `target` (parallel).
// Throws Error when target is empty.
std::vector<float> NearestDistances(const std::vector<Eigen::Vector3f>& query,
                                    const std::vector<Eigen::Vector3f>& target,
                                    std::vector<std::uint32_t>* nearest = nullptr);

// Point-to-plane distances |n_q . (p - q)| of the query points to their nearest target points q
// (indices from NearestDistances) with target normals n.
std::vector<float> SurfaceDistances(const std::vector<Eigen::Vector3f>& query,
                                    const std::vector<Eigen::Vector3f>& target,
                                    const std::vector<Eigen::Vector3f>& target_normals,
                                    const std::vector<std::uint32_t>& nearest);

struct CompareOptions {
  // Accuracy thresholds (m).
  std::vector<double> thresholds_m = {0.01, 0.02, 0.05};
  // A reference point counts as covered when the cloud has a point within this distance.
  double completeness_m = 0.05;

  void Check() const;
};

struct CompareResult {
  std::size_t cloud_points = 0;
  std::size_t ref_points = 0;
  DistanceStats accuracy;                         // cloud -> reference
  std::optional<DistanceStats> surface_accuracy;  // cloud -> reference surface (with normals)
  DistanceStats reference_to_cloud;               // reference -> cloud, all reference points
  double completeness = 0;                        // share of reference points covered
  // Over the reference points flagged in `ref_subset` (when given).
  std::optional<std::size_t> subset_points;
  std::optional<double> subset_completeness;
  std::vector<float> accuracy_distances;      // per cloud point
  std::vector<float> completeness_distances;  // per reference point
};

// `ref_subset`: empty, or one flag per reference point (restricted completeness).
// `ref_normals`: empty, or one unit normal per reference point (surface accuracy).
CompareResult CompareClouds(const std::vector<Eigen::Vector3f>& cloud,
                            const std::vector<Eigen::Vector3f>& reference,
                            const CompareOptions& options,
                            const std::vector<std::uint8_t>& ref_subset = {},
                            const std::vector<Eigen::Vector3f>& ref_normals = {});

// Completeness against another reference (e.g. the simulator's reference_observed.ply, the
// surfaces the sequence observed): the share of `reference` points with a `cloud` point within
// threshold_m. Throws Error on empty clouds or threshold <= 0.
double Completeness(const std::vector<Eigen::Vector3f>& cloud,
                    const std::vector<Eigen::Vector3f>& reference, double threshold_m);

// {"count", "mean", "median", "rms", "max", "within": {"0.01": share, ...}}
void WriteDistanceStatsJson(const DistanceStats& stats, JsonWriter& json);

}  // namespace pkslam::dense
