// Map files: an Atlas written and read back is the same Atlas (every count, pose bit for bit,
// BoW vectors, observations, covisibility, spanning tree, inertial chain and priors), writing
// the reloaded Atlas gives the same bytes, and a damaged or mismatched file is refused with a
// one-line error naming it.
#include "map_model/storage/map_file.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "core/sensor/test_rig_calibration.h"
#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/storage/atlas_storage.h"
#include "map_model/testing/synthetic_map.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

constexpr std::uint64_t kVocabulary = 0x1234abcd5678ef00ull;

void WriteBytes(const std::filesystem::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary) << bytes;
}

class MapFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("map_file");
    rig_ = testing::MakeStereoRig(Sensor::kStereoInertial);
    map_ = testing::MakeMap(&atlas_, testing::MakeScene(500, 7), rig_,
                            testing::MakeForwardPath(8, 0.15, 4), {});
    // Inertial state on the chain, a prior with a square root, a world change, a loop edge.
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    std::mt19937 rng(3);
    std::normal_distribution<double> n01;
    for (std::size_t k = 0; k < map_.keyframes.size(); ++k) {
      KeyFrame* kf = map_.keyframes[k].get();
      kf->mutable_imu(lock).state.velocity_world = Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      kf->mutable_imu(lock).state.bias.gyro = 1e-3 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      kf->mutable_imu(lock).state.valid = true;
      if (k == 0) continue;
      KeyFrame* previous = map_.keyframes[k - 1].get();
      PreintegratedImu pim;
      pim.dt = 0.05;
      pim.delta_R = SO3d::Exp(Eigen::Vector3d(0.01 * n01(rng), 0.02, -0.01));
      pim.delta_v = Eigen::Vector3d(n01(rng), 0.1, 0.2);
      pim.covariance = Eigen::Matrix<double, 15, 15>::Identity() * 1e-4;
      pim.steps.push_back({Eigen::Vector3d(0.1, 9.8, 0.2), Eigen::Vector3d(0.01, 0, 0), 0.005});
      map_.keyframes[0]->map()->inertial_chain().Append(lock, previous, kf, pim);
    }
    InertialStatePrior prior;
    prior.information = Eigen::Matrix<double, 15, 15>::Identity() * 42;
    prior.sqrt_information = Eigen::Matrix<double, 15, 15>::Identity() * std::sqrt(42.0);
    prior.map_id = map()->id();
    map_.keyframes[3]->mutable_imu(lock).prior = prior;
    map()->mutable_imu_status(lock).imu_initialized = true;
    map()->RecordWorldChange(
        lock, {WorldChange::Kind::kTransform, SO3d::Exp(Eigen::Vector3d(0, 0, 1)), 1.5});
    map_.keyframes[6]->AddLoopEdge(lock, map_.keyframes[1].get());
    map_.keyframes[1]->AddLoopEdge(lock, map_.keyframes[6].get());
  }
  Map* map() { return map_.keyframes[0]->map(); }

  std::filesystem::path Save(const Atlas& atlas, const std::string& name) {
    const std::filesystem::path file = dir_ / name;
    auto lock = MapReader(atlas).Lock();
    WriteMapFile(file, AtlasStorage::Snapshot(atlas, *rig_, kVocabulary));
    return file;
  }

  std::filesystem::path dir_;
  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticMap map_;
};

TEST_F(MapFileTest, RoundTripGivesTheSameMapAndTheSameBytes) {
  const auto first = Save(atlas_, "first.pkmap");
  Atlas loaded;
  {
    auto lock = MapEditor(&loaded).Write(MapEdit::kLoadMap);
    AtlasStorage::Restore(lock, ReadMapFile(first), rig_, &loaded);
  }
  ASSERT_EQ(loaded.NumMaps(), 1);
  const Map* a = map();
  const Map* b = loaded.current_map();
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->id(), a->id());
  ASSERT_EQ(b->NumKeyFrames(), a->NumKeyFrames());
  ASSERT_EQ(b->NumMapPoints(), a->NumMapPoints());
  EXPECT_GT(a->NumMapPoints(), 100);
  EXPECT_EQ(b->origin()->id(), a->origin()->id());
  EXPECT_EQ(b->NumWorldChanges(), 1);
  EXPECT_TRUE(b->imu_status().imu_initialized);
  for (const auto& [id, ka] : a->keyframes()) {
    const KeyFramePtr kb = b->KeyFrameById(id);
    ASSERT_NE(kb, nullptr);
    EXPECT_EQ(kb->camera_from_world().Matrix(), ka->camera_from_world().Matrix());  // exact
    EXPECT_EQ(kb->bow(), ka->bow());
    EXPECT_EQ(kb->feature_vector(), ka->feature_vector());
    EXPECT_EQ(kb->descriptors(), ka->descriptors());
    ASSERT_EQ(kb->size(), ka->size());
    for (int i = 0; i < ka->size(); ++i) {
      const MapPointPtr& pa = ka->map_point(i);
      const MapPointPtr& pb = kb->map_point(i);
      ASSERT_EQ(pa == nullptr, pb == nullptr) << "keyframe " << id << " slot " << i;
      if (pa) {
        EXPECT_EQ(pb->id(), pa->id());
      }
    }
    ASSERT_EQ(kb->CovisiblesByWeight().size(), ka->CovisiblesByWeight().size());
    for (std::size_t i = 0; i < ka->CovisiblesByWeight().size(); ++i) {
      EXPECT_EQ(kb->CovisiblesByWeight()[i]->id(), ka->CovisiblesByWeight()[i]->id());
      EXPECT_EQ(kb->Weight(kb->CovisiblesByWeight()[i]), ka->Weight(ka->CovisiblesByWeight()[i]));
    }
    EXPECT_EQ(kb->parent() ? kb->parent()->id() : -1, ka->parent() ? ka->parent()->id() : -1);
    EXPECT_EQ(kb->children().size(), ka->children().size());
    EXPECT_EQ(kb->loop_edges().size(), ka->loop_edges().size());
    EXPECT_EQ(kb->imu().previous() ? kb->imu().previous()->id() : -1,
              ka->imu().previous() ? ka->imu().previous()->id() : -1);
    EXPECT_EQ(kb->imu().state.velocity_world, ka->imu().state.velocity_world);
    ASSERT_EQ(kb->imu().from_previous.has_value(), ka->imu().from_previous.has_value());
    if (ka->imu().from_previous) {
      EXPECT_EQ(kb->imu().from_previous->delta_R.quaternion().coeffs(),
                ka->imu().from_previous->delta_R.quaternion().coeffs());
      EXPECT_EQ(kb->imu().from_previous->steps.size(), ka->imu().from_previous->steps.size());
    }
    EXPECT_EQ(kb->imu().prior.has_value(), ka->imu().prior.has_value());
  }
  for (const auto& [id, pa] : a->map_points()) {
    const MapPointPtr pb = b->MapPointById(id);
    ASSERT_NE(pb, nullptr);
    EXPECT_EQ(pb->position(), pa->position());
    EXPECT_EQ(pb->NumObservations(), pa->NumObservations());
    EXPECT_EQ(pb->observations().size(), pa->observations().size());
    EXPECT_EQ(pb->descriptor(), pa->descriptor());
    EXPECT_EQ(pb->reference_keyframe()->id(), pa->reference_keyframe()->id());
  }
  // Everything that is written was restored: the reloaded Atlas writes the same bytes (compared
  // as one bool: gtest would print a megabyte of binary on failure).
  const auto second = Save(loaded, "second.pkmap");
  EXPECT_TRUE(testing::ReadFileBytes(second) == testing::ReadFileBytes(first));
  // New objects continue after the loaded ids.
  EXPECT_EQ(loaded.NextKeyFrameId(), atlas_.NextKeyFrameId());
}

// The map's calibration keeps the IMU's errors: the gyro's scale factors (version 3) and the
// accelerometer's axis errors (version 4, row-major); a version 3 file (the same payload without
// the axis errors) reads with them zero.
TEST_F(MapFileTest, CalibrationKeepsTheImuErrorsAndVersion3ReadsZeroAxisErrors) {
  RigCalibration calibration = testing::EurocRigCalibration();
  calibration.time_offset_s = 2.5e-3;
  calibration.gyro_scale = Eigen::Vector3d(0.001, -0.0048, 0.0007);
  calibration.accel_axes << 0.0021, 1.3e-3, -0.4e-3,  //
      -0.9e-3, -0.0017, 2.2e-3,                       //
      0.0, 1.0 / 3.0 * 1e-3, 0.0005;
  AtlasRecord record;
  {
    auto lock = MapReader(atlas_).Lock();
    record = AtlasStorage::Snapshot(atlas_, *rig_, kVocabulary);
  }
  record.calibration = ToCalibrationRecord(calibration);
  const std::filesystem::path file = dir_ / "calibration.pkmap";
  WriteMapFile(file, record);
  const AtlasRecord back = ReadMapFile(file);
  ASSERT_TRUE(back.calibration.has_value());
  const RigCalibration restored = FromCalibrationRecord(*back.calibration);
  EXPECT_EQ(restored.time_offset_s, calibration.time_offset_s);
  EXPECT_EQ(restored.gyro_scale, calibration.gyro_scale);
  EXPECT_EQ(restored.accel_axes, calibration.accel_axes);  // exact, and not transposed

  // Version 3: the header's version, size and checksum over the payload less its last nine
  // doubles (cereal's portable binary array of 9 doubles: 72 bytes, no length).
  const std::string bytes = testing::ReadFileBytes(file);
  ASSERT_EQ(bytes[8], static_cast<char>(kMapFileVersion));
  const std::string payload = bytes.substr(24, bytes.size() - 24 - 9 * sizeof(double));
  std::string v3 = bytes.substr(0, 24) + payload;
  const auto put = [&](std::size_t at, std::uint64_t value, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) v3[at + i] = static_cast<char>((value >> (8 * i)) & 0xff);
  };
  put(8, 3, 4);
  put(12, payload.size(), 8);
  put(20, crc32(0L, reinterpret_cast<const Bytef*>(payload.data()), payload.size()), 4);
  WriteBytes(dir_ / "v3.pkmap", v3);
  const AtlasRecord old = ReadMapFile(dir_ / "v3.pkmap");
  ASSERT_TRUE(old.calibration.has_value());
  const RigCalibration old_calibration = FromCalibrationRecord(*old.calibration);
  EXPECT_EQ(old_calibration.gyro_scale, calibration.gyro_scale);
  EXPECT_TRUE(old_calibration.accel_axes.isZero());
  EXPECT_EQ(old.maps.size(), record.maps.size());
  // The same truncated payload claimed as version 4 does not decode.
  put(8, kMapFileVersion, 4);
  WriteBytes(dir_ / "short_v4.pkmap", v3);
  EXPECT_THROW(ReadMapFile(dir_ / "short_v4.pkmap"), InputError);
}

TEST_F(MapFileTest, DamagedFilesGiveOneLineErrorsNamingTheFile) {
  const auto good = Save(atlas_, "good.pkmap");
  const std::string bytes = testing::ReadFileBytes(good);
  auto expect_error = [&](const std::string& name, const std::string& content,
                          const std::string& reason) {
    const auto file = dir_ / name;
    WriteBytes(file, content);
    try {
      ReadMapFile(file);
      ADD_FAILURE() << name << " was accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(file.string()), std::string::npos) << what;
      EXPECT_NE(what.find(reason), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  expect_error("truncated.pkmap", bytes.substr(0, bytes.size() / 2), "truncated");
  expect_error("header_only.pkmap", bytes.substr(0, 10), "not a pkslam map file");
  std::string flipped = bytes;
  flipped[bytes.size() / 2] = static_cast<char>(flipped[bytes.size() / 2] ^ 0x10);
  expect_error("flipped.pkmap", flipped, "checksum");
  std::string version = bytes;
  version[8] = 99;
  expect_error("version.pkmap", version, "version 99");
  expect_error("text.pkmap", "%YAML:1.0\nCamera.fx: 1\n", "not a pkslam map file");
  EXPECT_THROW(ReadMapFile(dir_ / "missing.pkmap"), InputError);
}

TEST_F(MapFileTest, AnotherVocabularyOrCameraIsRefused) {
  const auto file = Save(atlas_, "map.pkmap");
  const AtlasRecord record = ReadMapFile(file);
  EXPECT_NO_THROW(CheckCompatible(file, record, kVocabulary, *rig_));
  EXPECT_THROW(CheckCompatible(file, record, kVocabulary + 1, *rig_), InputError);
  CameraRig other = *rig_;
  other.fx *= 1.01;
  EXPECT_THROW(CheckCompatible(file, record, kVocabulary, other), InputError);
  other = *rig_;
  other.sensor = Sensor::kMonocular;
  EXPECT_THROW(CheckCompatible(file, record, kVocabulary, other), InputError);
}

TEST_F(MapFileTest, RestoreNeedsAnEmptyAtlasAndItsWriteLock) {
  const auto file = Save(atlas_, "map.pkmap");
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kLoadMap);
    EXPECT_THROW(AtlasStorage::Restore(lock, ReadMapFile(file), rig_, &atlas_), Error);
  }
  // An empty Atlas, but the lock is another Atlas's: refused before anything changes.
  Atlas empty;
  auto other_lock = MapEditor(&atlas_).Write(MapEdit::kLoadMap);
  EXPECT_THROW(AtlasStorage::Restore(other_lock, ReadMapFile(file), rig_, &empty), Error);
  EXPECT_EQ(empty.NumMaps(), 1);
  EXPECT_EQ(empty.current_map()->NumKeyFrames(), 0);
}

}  // namespace
}  // namespace pkslam
