// Inertial state carried by frames and keyframes of inertial sensors (value types; the
// algorithms are in imu/, tracking/tracker_inertial.cc and mapping/).
//
// Ownership and locking: Frame::imu belongs to the tracking thread like the rest of a Frame.
// A keyframe's KeyFrameImu is guarded by the Atlas mutex like the keyframe's pose: KeyFrame::imu()
// reads it under the shared lock, KeyFrame::mutable_imu(lock) is the one door to change it and
// takes the write lock as a parameter; `previous()` / `next()` are the map's temporal chain,
// which only InertialChain (map_model/inertial_chain.h) links, splices and cuts.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "core/imu/imu_types.h"
#include "core/imu/inertial_state.h"
#include "map_model/map_ids.h"

namespace pkslam {

// A frame's IMU data: the preintegration since the previous frame (linearised at the bias
// tracking used) and the estimated state at the frame.
struct FrameImu {
  std::optional<PreintegratedImu> from_last_frame;
  InertialState state;
  // The camera-IMU time offset (s) the frame's stamp was shifted by (KeyFrameImu::time_offset_s).
  double time_offset_s = 0.0;
};

// A keyframe's IMU data: the preintegration from the previous keyframe of the chain and the
// estimated state. The chain's links are set only by InertialChain (map_model/inertial_chain.h).
struct KeyFrameImu {
  // Neighbours in the map's temporal chain, or nullptr.
  KeyFrame* previous() const { return previous_; }
  KeyFrame* next() const { return next_; }

  std::optional<PreintegratedImu> from_previous;  // spans previous->t_ns() .. this->t_ns()
  InertialState state;
  std::optional<InertialStatePrior> prior;  // see InertialStatePrior
  // The camera-IMU time offset (s) the keyframe's stamp was shifted by when it was tracked
  // (online calibration: its state sits at image stamp + this offset on the IMU clock).
  double time_offset_s = 0.0;

 private:
  friend class InertialChain;
  KeyFrame* previous_ = nullptr;
  KeyFrame* next_ = nullptr;
};

}  // namespace pkslam
