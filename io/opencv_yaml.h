// Typed reading of OpenCV FileStorage YAML files (ORB-SLAM3 settings, EuRoC sensor.yaml).
// These files carry `%YAML:1.0` and `!!opencv-matrix` tags that generic YAML parsers reject,
// so cv::FileStorage does the parsing. Every failure is an InputError naming the file, the
// key and, when the key can be found in the text, its line.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <opencv2/core/persistence.hpp>
#include <optional>
#include <string>
#include <vector>

namespace pkslam {

class OpenCvYamlFile {
 public:
  // Opens and parses `file`. Throws InputError when it is missing, empty or malformed.
  explicit OpenCvYamlFile(const std::filesystem::path& file);
  OpenCvYamlFile(const OpenCvYamlFile&) = delete;
  OpenCvYamlFile& operator=(const OpenCvYamlFile&) = delete;

  const std::filesystem::path& file() const { return file_; }
  bool Has(const std::string& key) const;
  bool IsString(const std::string& key) const;  // present and a string
  // Top-level keys in file order.
  std::vector<std::string> Keys() const;

  // Numbers accept YAML ints and reals. Int keys also accept reals with an integral value.
  double Double(const std::string& key) const;
  std::optional<double> OptionalDouble(const std::string& key) const;
  int Int(const std::string& key) const;
  std::optional<int> OptionalInt(const std::string& key) const;
  std::string String(const std::string& key) const;
  std::optional<std::string> OptionalString(const std::string& key) const;
  // A flow or block sequence of numbers; expected_size 0 accepts any non-empty length.
  std::vector<double> DoubleSequence(const std::string& key, std::size_t expected_size = 0) const;
  // A matrix node: `!!opencv-matrix` (rows, cols, dt, data) or a plain map with rows, cols,
  // data (EuRoC sensor.yaml). Row-major data of exactly rows*cols numbers.
  Eigen::MatrixXd Matrix(const std::string& key, int rows, int cols) const;
  // A 4x4 rigid transform: bottom row 0 0 0 1, rotation block orthonormal to 1e-4.
  Eigen::Matrix4d RigidTransform(const std::string& key) const;

  // Throws InputError(file, line of key, "key '<key>': <what>").
  [[noreturn]] void Fail(const std::string& key, const std::string& what) const;
  // 1-based line on which `key:` starts (0 when not found in the text).
  std::size_t LineOf(const std::string& key) const;

 private:
  void CheckNoDuplicateKeys() const;  // throws InputError at the second occurrence
  cv::FileNode RequiredNode(const std::string& key) const;
  double NumberOf(const cv::FileNode& node, const std::string& key, const char* where) const;

  std::filesystem::path file_;
  std::vector<std::string> lines_;  // the raw text, for line numbers in messages
  cv::FileStorage storage_;
};

}  // namespace pkslam
