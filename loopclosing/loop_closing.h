// The LoopClosing thread (ORB-SLAM3's LoopClosing): every keyframe local mapping hands over is
// checked against the keyframe database for a place seen before, in the same map (a loop) or
// in another map of the Atlas (a merge). A candidate is verified geometrically
// (loopclosing/place_verifier.h) and confirmed by covisible or following keyframes; then
//  - a loop is corrected: the query's covisibility window is moved by the loop Sim3, its
//    points fused with the other side's, the essential graph spreads the correction over the
//    map, and a global bundle adjustment runs in its own thread and is merged back into the
//    live map (new keyframes and points follow the spanning tree). Inertial maps with the IMU
//    initialised: a loop whose transform tilts gravity by more than inertial_max_tilt_rad (or
//    turns more than inertial_max_yaw_rad) is refused; otherwise it is reduced to yaw +
//    translation and the 4-DoF essential graph keeps every keyframe's roll and pitch, and
//    the global BA is the full visual-inertial BA (map_model/estimation/inertial_bundle_collect.h);
//  - a merge moves the current map into the recognised map (rigidly / by the Sim3; by yaw +
//    translation when both maps are gravity-aligned), welds the two sides by fusing points,
//    re-roots the spanning tree and optimises the essential graph of the merged map (4-DoF
//    when both are inertial), which becomes the Atlas' current map.
//
// Threads (docs/architecture.md): the queue, flags and statistics are guarded by `mutex_`;
// the map model by the Atlas mutex (shared while detecting, exclusive while correcting or
// merging). Local mapping is paused through MappingControl during corrections, merges and
// the write-back of a global BA. In synchronous mode (--deterministic) keyframes are processed
// inside InsertKeyFrame, on local mapping's own thread, and the global BA runs inline.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/sensor/camera_rig.h"
#include "core/util/annotated_mutex.h"
#include "loopclosing/place_verifier.h"
#include "map_model/atlas.h"
#include "map_model/estimation/bundle_collect.h"
#include "map_model/estimation/essential_graph_collect.h"

namespace pkslam {

struct LoopClosingOptions {
  PlaceVerifierOptions verifier;
  // Candidates per query from the database, for loops and for merges (ORB-SLAM3: 3).
  int candidates = 3;
  // Maps smaller than this are not searched for loops (ORB-SLAM3: 12; stereo/RGB-D: 5).
  int min_keyframes_mono = 12;
  int min_keyframes_stereo = 5;
  // Confirmations (the query, its covisibles, the next keyframes) needed (ORB-SLAM3: 3).
  int confirmations = 3;
  // Covisibles of the query asked to confirm at once (ORB-SLAM3: 5).
  int confirming_covisibles = 5;
  // A pending region is dropped after this many keyframes in a row fail to confirm it.
  int max_unconfirmed = 2;
  // No new loop search for this many keyframes after a correction (its fresh links would
  // otherwise be re-detected).
  int keyframes_after_loop = 10;
  // Map merging between maps of the Atlas.
  bool merge_maps = true;
  // Global bundle adjustment after a loop / merge.
  bool global_ba = true;
  BundleAdjustmentOptions global_ba_options;
  // Inertial maps with the IMU initialised and at most this many keyframes: the global BA is
  // the full visual-inertial BA (ORB-SLAM3 v1.0: FullInertialBA, 7 iterations, < 200
  // keyframes); larger inertial maps get the visual global BA.
  int inertial_global_ba_max_keyframes = 200;
  int inertial_global_ba_iterations = 7;
  // Inertial maps (IMU initialised): a loop is accepted only if its world correction turns
  // about the horizontal axes by less than inertial_max_tilt_rad (each rotation-vector
  // component) and about gravity by less than inertial_max_yaw_rad (ORB-SLAM3: 0.008, 0.349).
  double inertial_max_tilt_rad = 0.008;
  double inertial_max_yaw_rad = 0.349;
  // Metric maps (stereo, RGB-D, inertial with the IMU initialised; not visual monocular, whose
  // scale drifts): a loop is accepted only if it moves the query keyframe by at most
  // max_loop_correction_m + max_loop_correction_ratio * the path travelled (keyframe centres in
  // creation order) from the matched keyframe to the query. Not in ORB-SLAM3: a place that
  // repeats (same texture or structure a few metres apart) passes appearance, geometric and
  // temporal verification and then drags the map by the repeat's period (simulated V1_02
  // replay: a 2.15 m correction after 17 m of stereo-inertial flight whose drift was < 1 cm).
  // A ratio <= 0 disables the check.
  double max_loop_correction_m = 0.3;
  double max_loop_correction_ratio = 0.05;
  // Loop fusion: projection radius (px) of the other side's points into the corrected window.
  double fuse_radius = 4.0;
  // Process in the caller's thread, run the global BA inline (deterministic mode).
  bool synchronous = false;
  // First RANSAC seed of place verification (each verification draws the next one).
  std::uint64_t seed = 0;
  // Ceres threads of the essential graph (1 in deterministic mode).
  int num_threads = 1;

  void Check() const;
};

// One closed loop or merge, for stats.json.
struct LoopEvent {
  std::int64_t t_ns = 0;  // query keyframe's timestamp
  KeyFrameId query = kInvalidId;
  KeyFrameId matched = kInvalidId;
  MapId map = kInvalidId;          // map of the query (loops: the corrected map)
  MapId matched_map = kInvalidId;  // merges: the map the query's map was merged into
  int matches = 0;
  double correction_m = 0;   // how far the query keyframe moved (m)
  double detection_ms = 0;   // verification of the accepted candidate
  double correction_ms = 0;  // correction or merge including the essential graph
  double global_ba_ms = 0;   // global BA (0 if none finished)
};

struct LoopClosingStats {
  std::vector<LoopEvent> loops;
  std::vector<LoopEvent> merges;
  std::vector<double> detection_ms;  // per processed keyframe
  int keyframes = 0;                 // processed keyframes
  int tested_candidates = 0;         // database candidates put through verification
  int verified_regions = 0;          // candidates that passed verification (before confirmation)
  int rejected_regions = 0;          // pending regions dropped unconfirmed
  int rejected_inertial = 0;         // confirmed loops refused by the inertial tilt/yaw check
  int rejected_implausible = 0;      // confirmed loops refused: correction beyond the drift bound
  int global_ba_started = 0;
  int global_ba_finished = 0;
  int global_ba_aborted = 0;
};

// How loop closing pauses local mapping (set up by System).
struct MappingControl {
  std::function<void()> request_stop;
  std::function<bool()> is_stopped;  // also true once local mapping has finished for good
  std::function<void()> release;
};

class LoopClosing {
 public:
  LoopClosing(Atlas* atlas, Sensor sensor, MappingControl mapping, LoopClosingOptions options);
  ~LoopClosing();
  LoopClosing(const LoopClosing&) = delete;
  LoopClosing& operator=(const LoopClosing&) = delete;

  // Starts the thread (not in synchronous mode).
  void Start();
  // Processes what is queued, waits for a running global BA, stops the thread.
  void Finish();

  // Called by local mapping for every processed keyframe.
  void InsertKeyFrame(const KeyFramePtr& kf);
  // Blocks until the queue is empty and nothing is being processed (global BA may still run).
  void WaitUntilIdle();
  bool IsRunningGlobalBundle() const { return gba_running_.load(); }

  LoopClosingStats stats() const;

 private:
  void Run();
  void Process(const KeyFramePtr& kf);
  // Detection for one keyframe; returns an accepted region (loop or merge) or nullopt.
  std::optional<CommonRegion> Detect(const KeyFramePtr& kf, double* verification_ms);
  // Both return the map to optimise globally, or nullptr when the region became invalid.
  Map* CorrectLoop(const CommonRegion& region, LoopEvent* event);
  Map* MergeMaps(const CommonRegion& region, LoopEvent* event);
  // Moves the query's points onto the matched side (the query's matches and a projection of
  // the window points into every keyframe of `neighbourhood`, posed by `camera_from_world`),
  // updates their connections and returns the links that are new.
  std::map<KeyFrameId, std::vector<KeyFrameId>> FuseRegion(
      const MapWriteLock& lock, const CommonRegion& region,
      const std::vector<KeyFrame*>& neighbourhood,
      const std::map<KeyFrameId, Sim3d>& camera_from_world);
  // Global BA of `map` (inline or in its own thread); stops a running one first. The time is
  // written into the event stats_.loops/merges[index].
  void StartGlobalBundle(Map* map, bool merge, std::size_t index);
  void RunGlobalBundle(Map* map, bool merge, std::size_t index);
  void StopGlobalBundle();
  void PauseMapping();
  void ReleaseMapping();
  // Whether `map` is corrected in 4 DoF (inertial sensor, IMU initialised: gravity along -z),
  // and the essential graph's Dof for it. Atlas mutex held.
  bool UsesFourDof(const Map& map) const;
  PoseGraphDof GraphDof(const Map& map) const;
  // The inertial loop check (options inertial_max_*); true for non-inertial maps. Shared lock.
  bool AcceptsInertialLoop(const CommonRegion& region) const;
  // The drift bound of max_loop_correction_m / _ratio. Requires the Atlas mutex (shared).
  bool AcceptsLoopCorrection(const CommonRegion& region) const;

  Atlas* atlas_;
  Sensor sensor_;
  MappingControl mapping_;
  LoopClosingOptions options_;

  mutable Mutex mutex_;  // guards the members marked PKSLAM_GUARDED_BY(mutex_)
  ConditionVariable wake_;
  ConditionVariable idle_;
  std::deque<KeyFramePtr> queue_ PKSLAM_GUARDED_BY(mutex_);
  bool busy_ PKSLAM_GUARDED_BY(mutex_) = false;
  bool finish_requested_ PKSLAM_GUARDED_BY(mutex_) = false;
  LoopClosingStats stats_ PKSLAM_GUARDED_BY(mutex_);
  std::thread thread_;

  // Owned by the processing thread.
  std::optional<CommonRegion> pending_loop_;
  std::optional<CommonRegion> pending_merge_;
  int pending_loop_failures_ = 0;
  int pending_merge_failures_ = 0;
  KeyFrameId last_loop_kf_id_ = kInvalidId;
  std::uint64_t seed_ = 0;

  // Global BA thread: started and stopped by the processing thread only.
  std::thread gba_thread_;
  std::atomic<bool> gba_abort_{false};
  std::atomic<bool> gba_running_{false};
};

}  // namespace pkslam
