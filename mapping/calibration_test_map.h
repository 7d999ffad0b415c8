// Test fixture of the online-calibration tests (online_calibrator_test.cc,
// local_mapper_calibration_test.cc): twelve keyframes of a stereo map built in the rectified
// camera of the EuRoC calibration, which the Atlas holds as its calibration and the tests give
// as the prior (12 x 50 ms of data).
#pragma once

#include "core/sensor/test_rig_calibration.h"
#include "map_model/atlas.h"
#include "map_model/map_editor.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam::testing {

struct CalibrationTestMap {
  CalibrationTestMap() {
    file = EurocRigCalibration();
    shape.sensor = Sensor::kStereo;
    shape.pyramid = ScalePyramid(8, 1.2);
    setup = BuildRig(file, shape);
    {
      auto lock = MapEditor(&atlas).Write(MapEdit::kFixture);
      atlas.SetCalibration(lock, file, setup);
    }
    FrameOptions frames;
    frames.pixel_noise = 0.5;
    map = MakeMap(&atlas, MakeScene(600, 11), setup.rig, MakeForwardPath(12, 0.15, 3), frames);
  }

  Atlas atlas;
  RigCalibration file;
  RigShape shape;
  RigSetup setup;
  SyntheticMap map;
};

}  // namespace pkslam::testing
