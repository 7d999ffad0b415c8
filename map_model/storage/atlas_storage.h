// Between a live Atlas and its records (map_model/storage/map_records.h): the one class that
// reads and rebuilds the map model's private state for map files (a friend of Atlas, Map,
// KeyFrame and MapPoint, so their public interfaces stay as they are).
#pragma once

#include <memory>

#include "core/sensor/camera_rig.h"
#include "map_model/atlas.h"
#include "map_model/storage/map_records.h"

namespace pkslam {

class AtlasStorage {
 public:
  // Every non-empty map of `atlas` with its live keyframes and points. Caller holds the Atlas
  // lock (shared). `vocabulary_fingerprint`: Vocabulary::Fingerprint() of the run's vocabulary.
  static AtlasRecord Snapshot(const Atlas& atlas, const CameraRig& rig,
                              std::uint64_t vocabulary_fingerprint);

  // Rebuilds the maps of `record` in `atlas`, which must hold only empty maps (a new system's
  // Atlas): those are dropped, the loaded maps take their ids, the loaded current map becomes
  // current, the id counters continue after the loaded ones, and every keyframe enters the
  // Atlas's keyframe database. Every keyframe uses `rig` (checked against record.camera by the
  // caller: map_file.h CheckCompatible). `lock` holds `atlas` (MapEdit::kLoadMap). Throws
  // Error on a record whose links name missing objects.
  static void Restore(const MapWriteLock& lock, const AtlasRecord& record,
                      std::shared_ptr<const CameraRig> rig, Atlas* atlas);
};

// The calibration of a map file and back (AtlasRecord::calibration).
CalibrationRecord ToCalibrationRecord(const RigCalibration& calibration);
// Throws OptionError when a recorded camera is not a valid pinhole.
RigCalibration FromCalibrationRecord(const CalibrationRecord& record);

}  // namespace pkslam
