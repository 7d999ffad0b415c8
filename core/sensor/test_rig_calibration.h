// The EuRoC stereo rig's calibration (the cameras and extrinsics of core/camera/test_cameras.h,
// no time offset, no gyro scale error) for tests that build rigs, maps or reports from it.
#pragma once

#include "core/camera/test_cameras.h"
#include "core/sensor/rig_calibration.h"

namespace pkslam::testing {

inline RigCalibration EurocRigCalibration() {
  RigCalibration c;
  c.cameras = {EurocCam0(), EurocCam1()};
  c.body_from_cam0 = EurocBodyFromCam0();
  c.cam1_from_cam0 = EurocCam1FromCam0();
  return c;
}

}  // namespace pkslam::testing
