#include "io/opencv_yaml.h"

#include <fmt/format.h>

#include <Eigen/LU>
#include <cmath>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <regex>

#include "core/util/error.h"

namespace pkslam {

OpenCvYamlFile::OpenCvYamlFile(const std::filesystem::path& file) : file_(file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(file, "file not found");
  {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, "cannot open file for reading");
    std::string line;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      lines_.push_back(line);
    }
  }
  bool blank = true;
  for (std::size_t i = 0; i < lines_.size(); ++i) {
    if (lines_[i].find_first_not_of(" \t") != std::string::npos) blank = false;
    // OpenCV 4.6's YAML parser loops forever on some inputs with a NUL byte (found by
    // fuzz/settings_fuzzer.cc); a text settings file has none.
    if (lines_[i].find('\0') != std::string::npos) {
      throw InputError(file, i + 1, "NUL byte: not a text file");
    }
  }
  if (blank) throw InputError(file, "empty file");
  CheckNoDuplicateKeys();
  if (lines_.front().rfind("%YAML", 0) != 0) {
    throw InputError(file, 1, "not an OpenCV YAML file (the first line must be '%YAML:1.0')");
  }
  try {
    storage_.open(file.string(), cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    // OpenCV's parser reports "<file>(<line>): <reason>" in the function field.
    const std::regex where_pattern(R"(\((\d+)\): (.*)$)");
    std::smatch match;
    const std::string where = e.func;
    if (std::regex_search(where, match, where_pattern)) {
      throw InputError(file, std::stoul(match[1].str()), "malformed YAML: " + match[2].str());
    }
    throw InputError(file, "malformed YAML: " + e.err);
  } catch (const std::exception& e) {
    // OpenCV 4.6's parser fails with std::length_error, not its own error, on an indented
    // empty key (" : 1"); name that line.
    for (std::size_t i = 0; i < lines_.size(); ++i) {
      const std::size_t start = lines_[i].find_first_not_of(" \t");
      if (start != std::string::npos && lines_[i][start] == ':') {
        throw InputError(file, i + 1, "malformed YAML: an empty key");
      }
    }
    throw InputError(file, fmt::format("malformed YAML (OpenCV's parser failed: {})", e.what()));
  }
  if (!storage_.isOpened()) throw InputError(file, "cannot parse as OpenCV YAML");
  if (!storage_.root().isMap()) throw InputError(file, "expected a map of keys at top level");
}

void OpenCvYamlFile::CheckNoDuplicateKeys() const {
  // OpenCV keeps one of two equal keys without a word; a file with `intrinsics:` twice ran on
  // whichever it kept. Top-level keys only (nested maps such as T_BS's rows/cols/data repeat
  // legitimately across parents).
  static const std::regex kTopLevelKey(R"(^([A-Za-z_][A-Za-z0-9_.\-]*)[ \t]*:)");
  std::map<std::string, std::size_t> first_line;
  for (std::size_t i = 0; i < lines_.size(); ++i) {
    std::smatch match;
    if (!std::regex_search(lines_[i], match, kTopLevelKey)) continue;
    const auto [it, inserted] = first_line.emplace(match[1].str(), i + 1);
    if (!inserted) {
      throw InputError(file_, i + 1,
                       fmt::format("key '{}' appears twice (first on line {}); OpenCV would "
                                   "silently use one of them: delete the other",
                                   match[1].str(), it->second));
    }
  }
}

bool OpenCvYamlFile::Has(const std::string& key) const {
  const cv::FileNode node = storage_[key];
  return !node.empty() && !node.isNone();
}

bool OpenCvYamlFile::IsString(const std::string& key) const {
  return Has(key) && storage_[key].isString();
}

std::vector<std::string> OpenCvYamlFile::Keys() const { return storage_.root().keys(); }

std::size_t OpenCvYamlFile::LineOf(const std::string& key) const {
  for (std::size_t i = 0; i < lines_.size(); ++i) {
    const std::string& line = lines_[i];
    const std::size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line.compare(start, key.size(), key) != 0) continue;
    const std::size_t after = line.find_first_not_of(" \t", start + key.size());
    if (after != std::string::npos && line[after] == ':') return i + 1;
  }
  return 0;
}

void OpenCvYamlFile::Fail(const std::string& key, const std::string& what) const {
  throw InputError(file_, LineOf(key), fmt::format("key '{}': {}", key, what));
}

cv::FileNode OpenCvYamlFile::RequiredNode(const std::string& key) const {
  if (!Has(key)) Fail(key, "missing (required)");
  return storage_[key];
}

double OpenCvYamlFile::NumberOf(const cv::FileNode& node, const std::string& key,
                                const char* where) const {
  if (node.isInt()) return static_cast<int>(node);
  if (node.isReal()) {
    const double value = static_cast<double>(node);
    if (!std::isfinite(value)) Fail(key, fmt::format("{}is not finite", where));
    return value;
  }
  if (node.isString()) {
    Fail(key, fmt::format("{}expected a number, found '{}'", where, node.string()));
  }
  Fail(key, fmt::format("{}expected a number", where));
}

double OpenCvYamlFile::Double(const std::string& key) const {
  return NumberOf(RequiredNode(key), key, "");
}

std::optional<double> OpenCvYamlFile::OptionalDouble(const std::string& key) const {
  if (!Has(key)) return std::nullopt;
  return Double(key);
}

int OpenCvYamlFile::Int(const std::string& key) const {
  const double value = NumberOf(RequiredNode(key), key, "");
  if (value != std::floor(value) || std::abs(value) > 2e9) {
    Fail(key, fmt::format("expected an integer, found {}", value));
  }
  return static_cast<int>(value);
}

std::optional<int> OpenCvYamlFile::OptionalInt(const std::string& key) const {
  if (!Has(key)) return std::nullopt;
  return Int(key);
}

std::string OpenCvYamlFile::String(const std::string& key) const {
  const cv::FileNode node = RequiredNode(key);
  if (!node.isString()) Fail(key, "expected a string");
  return node.string();
}

std::optional<std::string> OpenCvYamlFile::OptionalString(const std::string& key) const {
  if (!Has(key)) return std::nullopt;
  return String(key);
}

std::vector<double> OpenCvYamlFile::DoubleSequence(const std::string& key,
                                                   std::size_t expected_size) const {
  const cv::FileNode node = RequiredNode(key);
  if (!node.isSeq()) Fail(key, "expected a sequence of numbers [a, b, ...]");
  std::vector<double> values;
  for (const cv::FileNode& element : node) {
    values.push_back(NumberOf(element, key, "sequence element: "));
  }
  if (values.empty()) Fail(key, "empty sequence");
  if (expected_size != 0 && values.size() != expected_size) {
    Fail(key, fmt::format("expected {} numbers, found {}", expected_size, values.size()));
  }
  return values;
}

Eigen::MatrixXd OpenCvYamlFile::Matrix(const std::string& key, int rows, int cols) const {
  const cv::FileNode node = RequiredNode(key);
  if (!node.isMap()) Fail(key, "expected a matrix (rows, cols, data)");
  const auto dim = [&](const char* name) {
    const cv::FileNode d = node[name];
    if (d.empty() || !d.isInt()) Fail(key, fmt::format("matrix needs an integer '{}'", name));
    return static_cast<int>(d);
  };
  const int file_rows = dim("rows");
  const int file_cols = dim("cols");
  if (file_rows != rows || file_cols != cols) {
    Fail(key,
         fmt::format("expected a {}x{} matrix, found {}x{}", rows, cols, file_rows, file_cols));
  }
  const cv::FileNode dt = node["dt"];
  if (!dt.empty() && !dt.isString()) Fail(key, "matrix 'dt' must be a type letter (f, d)");
  const cv::FileNode data = node["data"];
  if (data.empty() || !data.isSeq()) Fail(key, "matrix needs a 'data' sequence");
  if (data.size() != static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols)) {
    Fail(key, fmt::format("matrix data has {} numbers, expected {}", data.size(), rows * cols));
  }
  Eigen::MatrixXd m(rows, cols);
  int i = 0;
  for (const cv::FileNode& element : data) {
    m(i / cols, i % cols) = NumberOf(element, key, "matrix data: ");
    ++i;
  }
  return m;
}

Eigen::Matrix4d OpenCvYamlFile::RigidTransform(const std::string& key) const {
  Eigen::Matrix4d m = Matrix(key, 4, 4);
  if (!m.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1), 1e-9)) {
    Fail(key, "not a rigid transform: the last row must be 0 0 0 1");
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double orthonormality = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm();
  // Negated so that NaN fails: with entries like 1e200, R^T R is inf - inf.
  if (!(orthonormality <= 1e-4) || !(r.determinant() > 0)) {
    Fail(key, fmt::format("not a rigid transform: the rotation block is not a rotation "
                          "(|R^T R - I| = {:.2e}, det = {:.4f})",
                          orthonormality, r.determinant()));
  }
  return m;
}

}  // namespace pkslam
