// Test-only helpers: small synthetic EuRoC / TUM RGB-D datasets written to a temp directory.
#pragma once

#include <fmt/format.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

namespace pkslam::testing {

inline void WriteText(const std::filesystem::path& file, const std::string& text) {
  std::filesystem::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
}

// The EuRoC cam0 / cam1 sensor.yaml (T_BS and calibration as in the real dataset).
inline std::string EurocCameraYaml(int cam) {
  const char* t_bs =
      cam == 0 ? "[0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,\n"
                 "         0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,\n"
                 "        -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,\n"
                 "         0.0, 0.0, 0.0, 1.0]"
               : "[0.0125552670891, -0.999755099723, 0.0182237714554, -0.0198435579556,\n"
                 "         0.999598781151, 0.0130119051815, 0.0251588363115, 0.0453689425024,\n"
                 "        -0.0253898008918, 0.0179005838253, 0.999517347078, 0.00786212447038,\n"
                 "         0.0, 0.0, 0.0, 1.0]";
  const char* intrinsics =
      cam == 0 ? "[458.654, 457.296, 367.215, 248.375]" : "[457.587, 456.134, 379.999, 255.238]";
  const char* distortion = cam == 0 ? "[-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]"
                                    : "[-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05]";
  return fmt::format(
      "%YAML:1.0\nsensor_type: camera\ncomment: cam{}\nT_BS:\n  cols: 4\n  rows: 4\n  data: {}\n"
      "rate_hz: 20\nresolution: [752, 480]\ncamera_model: pinhole\nintrinsics: {} #fu, fv, cu, "
      "cv\ndistortion_model: radial-tangential\ndistortion_coefficients: {}\n",
      cam, t_bs, intrinsics, distortion);
}

inline std::string EurocImuYaml() {
  return "%YAML:1.0\nsensor_type: imu\nT_BS:\n  cols: 4\n  rows: 4\n"
         "  data: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, "
         "1.0]\n"
         "rate_hz: 200\ngyroscope_noise_density: 1.6968e-04\ngyroscope_random_walk: 1.9393e-05\n"
         "accelerometer_noise_density: 2.0000e-3\naccelerometer_random_walk: 3.0000e-3\n";
}

// A small grey PNG whose pixels encode `seed`.
inline void WriteTestImage(const std::filesystem::path& file, int seed, int type = CV_8UC1) {
  std::filesystem::create_directories(file.parent_path());
  cv::Mat image(48, 64, type, cv::Scalar::all(seed % 250));
  cv::imwrite(file.string(), image);
}

// A EuRoC dataset under `root`: cam0 and cam1 frames at 20 Hz starting at t0 (ns), IMU at
// 200 Hz over the same span. Image files are written for every frame.
struct EurocFixture {
  std::int64_t t0_ns = 1'403'715'273'262'142'976;
  int frames = 5;
  bool with_cam1 = true;
  bool with_imu = true;

  std::int64_t FrameT(int i) const { return t0_ns + std::int64_t{50'000'000} * i; }

  void Write(const std::filesystem::path& root) const {
    const std::filesystem::path mav0 = root / "mav0";
    for (int cam = 0; cam < (with_cam1 ? 2 : 1); ++cam) {
      const std::filesystem::path dir = mav0 / fmt::format("cam{}", cam);
      WriteText(dir / "sensor.yaml", EurocCameraYaml(cam));
      std::string csv = "#timestamp [ns],filename\n";
      for (int i = 0; i < frames; ++i) {
        csv += fmt::format("{},{}.png\n", FrameT(i), FrameT(i));
        WriteTestImage(dir / "data" / fmt::format("{}.png", FrameT(i)), 10 * i + cam);
      }
      WriteText(dir / "data.csv", csv);
    }
    if (with_imu) {
      WriteText(mav0 / "imu0" / "sensor.yaml", EurocImuYaml());
      std::string csv = "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n";
      for (int i = 0; i <= (frames - 1) * 10; ++i) {
        csv += fmt::format("{},0.01,-0.02,0.03,9.8,{}.5,-0.1\n",
                           t0_ns + std::int64_t{5'000'000} * i, i);
      }
      WriteText(mav0 / "imu0" / "data.csv", csv);
    }
  }
};

}  // namespace pkslam::testing
