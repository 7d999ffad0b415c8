#include "map_model/storage/map_file.h"

#include <zlib.h>

#include <cereal/archives/portable_binary.hpp>
#include <cereal/types/array.hpp>
#include <cereal/types/optional.hpp>
#include <cereal/types/string.hpp>
#include <cereal/types/utility.hpp>
#include <cereal/types/vector.hpp>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/sensor/sensor.h"
#include "core/util/error.h"
#include "core/util/output_file.h"

// cereal finds these by argument-dependent lookup: Eigen's and pkslam's value types.
namespace Eigen {
template <class Archive, typename S, int R, int C, int O, int MR, int MC>
void serialize(Archive& ar, Matrix<S, R, C, O, MR, MC>& m) {
  static_assert(R > 0 && C > 0, "fixed-size matrices only");
  for (Index i = 0; i < m.size(); ++i) ar(m.data()[i]);
}
}  // namespace Eigen

namespace pkslam {

template <class Archive>
void save(Archive& ar, const SO3d& r) {
  const Eigen::Quaterniond& q = r.quaternion();
  ar(q.x(), q.y(), q.z(), q.w());
}
template <class Archive>
void load(Archive& ar, SO3d& r) {
  double x = 0, y = 0, z = 0, w = 1;
  ar(x, y, z, w);
  r = SO3d::FromStoredQuaternion(Eigen::Quaterniond(w, x, y, z));
}
template <class Archive>
void save(Archive& ar, const SE3d& t) {
  ar(t.so3(), t.translation());
}
template <class Archive>
void load(Archive& ar, SE3d& t) {
  SO3d r;
  Eigen::Vector3d p;
  ar(r, p);
  t = SE3d(r, p);
}
template <class Archive>
void serialize(Archive& ar, Descriptor& d) {
  ar(cereal::binary_data(d.bytes.data(), d.bytes.size()));
}
template <class Archive>
void serialize(Archive& ar, BowEntry& e) {
  ar(e.word_id, e.weight);
}
template <class Archive>
void serialize(Archive& ar, ImuBias& b) {
  ar(b.gyro, b.accel);
}
template <class Archive>
void serialize(Archive& ar, ImuNoise& n) {
  ar(n.gyro_noise_density, n.accel_noise_density, n.gyro_random_walk, n.accel_random_walk,
     n.rate_hz);
}
template <class Archive>
void serialize(Archive& ar, NavState& s) {
  ar(s.world_from_body, s.velocity_world);
}
template <class Archive>
void serialize(Archive& ar, PreintegratedImu::Step& s) {
  ar(s.accel, s.gyro, s.dt);
}
template <class Archive>
void save(Archive& ar, const PreintegratedImu& p) {
  ar(p.dt, p.delta_R, p.delta_v, p.delta_p, p.J_R_bg, p.J_v_bg, p.J_v_ba, p.J_p_bg, p.J_p_ba,
     p.covariance, p.bias, p.noise, static_cast<std::int32_t>(p.scheme), p.average_accel,
     p.average_gyro, p.steps);
}
template <class Archive>
void load(Archive& ar, PreintegratedImu& p) {
  std::int32_t scheme = 0;
  ar(p.dt, p.delta_R, p.delta_v, p.delta_p, p.J_R_bg, p.J_v_bg, p.J_v_ba, p.J_p_bg, p.J_p_ba,
     p.covariance, p.bias, p.noise, scheme, p.average_accel, p.average_gyro, p.steps);
  p.scheme = static_cast<ImuIntegrationScheme>(scheme);
}
template <class Archive>
void serialize(Archive& ar, InertialState& s) {
  ar(s.velocity_world, s.bias, s.valid);
}
template <class Archive>
void serialize(Archive& ar, InertialStatePrior& p) {
  ar(p.mean, p.bias_mean, p.information, p.sqrt_information, p.map_id, p.map_change_index,
     p.world_transforms);
}
template <class Archive>
void serialize(Archive& ar, KeyPointRecord& k) {
  ar(k.x, k.y, k.size, k.angle, k.response, k.octave);
}
template <class Archive>
void serialize(Archive& ar, KeyFrameRecord& k) {
  ar(k.id, k.frame_id, k.t_ns, k.keypoints, k.keypoints_undistorted, k.right_u, k.depth,
     k.depth_sigma, k.descriptors, k.bow, k.feature_vector, k.camera_from_world, k.map_points,
     k.connections, k.parent, k.loop_edges, k.not_erase, k.camera_from_parent,
     k.imu_from_previous, k.imu_previous, k.imu_next, k.imu_state, k.imu_prior);
}
template <class Archive>
void serialize(Archive& ar, MapPointRecord& p) {
  ar(p.id, p.first_keyframe, p.reference_keyframe, p.position, p.normal, p.descriptor,
     p.min_distance, p.max_distance, p.observations, p.visible, p.found);
}
template <class Archive>
void serialize(Archive& ar, WorldChangeRecord& c) {
  ar(c.kind, c.rotation, c.scale);
}
template <class Archive>
void serialize(Archive& ar, MapRecord& m) {
  ar(m.id, m.origin, m.max_keyframe_id, m.change_index, m.imu_initialized, m.inertial_ba1_done,
     m.inertial_ba2_done, m.gravity_refinement_observability, m.imu_init_t_ns, m.world_changes,
     m.applied_scale, m.world_transforms, m.keyframes, m.points);
}
template <class Archive>
void serialize(Archive& ar, CameraRecord& c) {
  ar(c.sensor, c.model, c.fx, c.fy, c.cx, c.cy, c.bf, c.body_from_camera);
}
template <class Archive>
void serialize(Archive& ar, AtlasRecord& a) {
  ar(a.vocabulary_fingerprint, a.camera, a.current_map, a.next_map_id, a.next_frame_id,
     a.next_keyframe_id, a.next_point_id, a.maps);
}
template <class Archive>
void serialize(Archive& ar, CalibrationRecord::Camera& c) {
  ar(c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.distortion);
}
template <class Archive>
void serialize(Archive& ar, CalibrationRecord& c) {
  ar(c.cameras, c.body_from_cam0, c.cam1_from_cam0, c.time_offset_s, c.keyframe_time_offsets);
}

namespace {

constexpr char kMagic[8] = {'P', 'K', 'S', 'L', 'A', 'M', 'A', 'P'};
constexpr std::size_t kHeaderSize = 24;

std::uint32_t Crc32(std::string_view bytes) {
  uLong crc = crc32(0L, Z_NULL, 0);
  // zlib takes uInt lengths: feed large payloads in chunks.
  constexpr std::size_t kChunk = 1u << 30;
  for (std::size_t at = 0; at < bytes.size(); at += kChunk) {
    const std::size_t n = std::min(kChunk, bytes.size() - at);
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data() + at), static_cast<uInt>(n));
  }
  return static_cast<std::uint32_t>(crc);
}

template <typename T>
void PutLittleEndian(std::string* out, T value) {
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    out->push_back(static_cast<char>((static_cast<std::uint64_t>(value) >> (8 * i)) & 0xff));
  }
}

template <typename T>
T GetLittleEndian(const std::string& in, std::size_t at) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    v |= static_cast<std::uint64_t>(static_cast<unsigned char>(in[at + i])) << (8 * i);
  }
  return static_cast<T>(v);
}

bool Close(double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(b)); }

}  // namespace

void WriteMapFile(const std::filesystem::path& file, const AtlasRecord& record) {
  std::ostringstream payload_stream(std::ios::binary);
  {
    cereal::PortableBinaryOutputArchive archive(payload_stream);
    archive(record);
    archive(record.calibration);             // version 2
    std::array<double, 3> gyro_scale{};
    if (record.calibration) gyro_scale = record.calibration->gyro_scale;
    archive(gyro_scale);  // version 3
    std::array<double, 9> accel_axes{};
    if (record.calibration) accel_axes = record.calibration->accel_axes;
    archive(accel_axes);  // version 4
  }
  const std::string payload = payload_stream.str();
  std::string out;
  out.reserve(kHeaderSize + payload.size());
  out.append(kMagic, sizeof(kMagic));
  PutLittleEndian<std::uint32_t>(&out, kMapFileVersion);
  PutLittleEndian<std::uint64_t>(&out, payload.size());
  PutLittleEndian<std::uint32_t>(&out, Crc32(payload));
  out += payload;
  WriteFileAtomically(file, out);
}

AtlasRecord ReadMapFile(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    throw InputError(file, std::filesystem::is_directory(file, ec)
                               ? "is a folder, not a map file (pkslam run --save-map FILE)"
                               : "map file not found");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot open map file");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < kHeaderSize || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    throw InputError(file, "not a pkslam map file (no PKSLAMAP header)");
  }
  const auto version = GetLittleEndian<std::uint32_t>(bytes, 8);
  if (version < kOldestMapFileVersion || version > kMapFileVersion) {
    throw InputError(file, fmt::format("map file format version {}, this pkslam reads versions "
                                       "{}-{}",
                                       version, kOldestMapFileVersion, kMapFileVersion));
  }
  const auto size = GetLittleEndian<std::uint64_t>(bytes, 12);
  const auto crc = GetLittleEndian<std::uint32_t>(bytes, 20);
  if (bytes.size() - kHeaderSize != size) {
    throw InputError(file, fmt::format("truncated or extended map file: payload {} bytes, header "
                                       "says {}",
                                       bytes.size() - kHeaderSize, size));
  }
  const std::string_view payload(bytes.data() + kHeaderSize, size);
  if (Crc32(payload) != crc) {
    throw InputError(file, "corrupted map file: payload checksum mismatch");
  }
  AtlasRecord record;
  try {
    std::istringstream payload_stream(std::string(payload), std::ios::binary);
    cereal::PortableBinaryInputArchive archive(payload_stream);
    archive(record);
    if (version >= 2) archive(record.calibration);
    if (version >= 3) {
      std::array<double, 3> gyro_scale{};
      archive(gyro_scale);
      if (record.calibration) record.calibration->gyro_scale = gyro_scale;
    }
    if (version >= 4) {
      std::array<double, 9> accel_axes{};
      archive(accel_axes);
      if (record.calibration) record.calibration->accel_axes = accel_axes;
    }
  } catch (const std::exception& e) {
    throw InputError(file, fmt::format("map file payload does not decode: {}", e.what()));
  }
  return record;
}

void CheckCompatible(const std::filesystem::path& file, const AtlasRecord& record,
                     std::uint64_t vocabulary_fingerprint, const CameraRig& rig) {
  if (record.vocabulary_fingerprint != vocabulary_fingerprint) {
    throw InputError(file, fmt::format("map built with another vocabulary (fingerprint {:016x}, "
                                       "this run's {:016x})",
                                       record.vocabulary_fingerprint, vocabulary_fingerprint));
  }
  const CameraRecord& c = record.camera;
  if (c.sensor != static_cast<std::int32_t>(rig.sensor)) {
    throw InputError(file, fmt::format("map built for sensor {}, this run is {}",
                                       SensorName(static_cast<Sensor>(c.sensor)),
                                       SensorName(rig.sensor)));
  }
  if (!Close(c.fx, rig.fx) || !Close(c.fy, rig.fy) || !Close(c.cx, rig.cx) ||
      !Close(c.cy, rig.cy) || !Close(c.bf, rig.bf) || c.model != rig.camera.ToString()) {
    throw InputError(file, fmt::format("map built with camera '{}' (fx {} fy {} cx {} cy {} bf {}), "
                                       "this run's is '{}' (fx {} fy {} cx {} cy {} bf {})",
                                       c.model, c.fx, c.fy, c.cx, c.cy, c.bf,
                                       rig.camera.ToString(), rig.fx, rig.fy, rig.cx, rig.cy,
                                       rig.bf));
  }
  const SE3d d = c.body_from_camera.Inverse() * rig.body_from_camera;
  if (d.translation().norm() > 1e-6 || d.so3().Log().norm() > 1e-6) {
    throw InputError(file, "map built with another camera-IMU extrinsic (T_BS)");
  }
}

}  // namespace pkslam
