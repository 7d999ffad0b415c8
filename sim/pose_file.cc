#include "sim/pose_file.h"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <string>

#include "core/util/error.h"

namespace pkslam::sim {

bool ParseTimestampNs(std::string_view text, bool integer_is_ns, std::int64_t* t_ns) {
  const std::size_t dot = text.find('.');
  const std::string_view whole = text.substr(0, dot);
  std::int64_t integer = 0;
  if (whole.empty()) return false;
  auto [end, ec] = std::from_chars(whole.data(), whole.data() + whole.size(), integer);
  if (ec != std::errc() || end != whole.data() + whole.size() || integer < 0) return false;
  if (dot == std::string_view::npos) {
    *t_ns = integer_is_ns ? integer : integer * 1'000'000'000;
    return true;
  }
  std::string_view frac = text.substr(dot + 1);
  std::int64_t ns = 0;
  int digits = 0;
  for (char c : frac) {
    if (c < '0' || c > '9') return false;
    if (digits < 9) {
      ns = ns * 10 + (c - '0');
      ++digits;
    }
  }
  for (; digits < 9; ++digits) ns *= 10;
  *t_ns = integer * 1'000'000'000 + ns;
  return true;
}

std::vector<PoseSample> ReadPoseFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open trajectory file");
  std::vector<PoseSample> out;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const bool csv = line.find(',') != std::string::npos;
    for (char& c : line) {
      if (c == ',' || c == '\t') c = ' ';
    }
    std::vector<std::string_view> fields;
    std::string_view rest(line);
    while (!rest.empty()) {
      const std::size_t b = rest.find_first_not_of(' ');
      if (b == std::string_view::npos) break;
      rest.remove_prefix(b);
      const std::size_t e = rest.find(' ');
      fields.push_back(rest.substr(0, e));
      rest.remove_prefix(e == std::string_view::npos ? rest.size() : e);
    }
    if (fields.size() < 8) {
      throw InputError(path, line_no, fmt::format("expected 8 values, found {}", fields.size()));
    }
    PoseSample s;
    if (!ParseTimestampNs(fields[0], csv, &s.t_ns)) {
      throw InputError(path, line_no, fmt::format("bad timestamp '{}'", fields[0]));
    }
    std::array<double, 7> v{};
    for (int i = 0; i < 7; ++i) {
      const std::string_view f = fields[i + 1];
      auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), v[i]);
      if (ec != std::errc() || end != f.data() + f.size() || !std::isfinite(v[i])) {
        throw InputError(path, line_no, fmt::format("bad number '{}'", f));
      }
    }
    // TUM: x y z qx qy qz qw; EuRoC csv: x y z qw qx qy qz.
    const Eigen::Quaterniond q = csv ? Eigen::Quaterniond(v[3], v[4], v[5], v[6])
                                     : Eigen::Quaterniond(v[6], v[3], v[4], v[5]);
    if (std::abs(q.norm() - 1.0) > 1e-2) {
      throw InputError(path, line_no, fmt::format("quaternion norm {:.4f} is not 1", q.norm()));
    }
    if (!out.empty() && s.t_ns <= out.back().t_ns) {
      throw InputError(path, line_no, "timestamps not strictly increasing");
    }
    s.world_from_body = SE3d(q, Eigen::Vector3d(v[0], v[1], v[2]));
    out.push_back(s);
  }
  if (out.size() < 2) throw InputError(path, "fewer than two poses");
  return out;
}

}  // namespace pkslam::sim
