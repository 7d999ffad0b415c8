#include "io/trajectory.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/output_file.h"

namespace pkslam {
namespace {

// A timestamp at or above this is taken to be in nanoseconds (1e12 s would be the year 33658).
constexpr double kNanosecondThreshold = 1e12;
// Quaternions whose norm differs from 1 by more than this are reported (then normalised).
constexpr double kQuaternionNormWarning = 1e-2;
constexpr double kQuaternionNormMinimum = 1e-9;

std::string_view Trim(std::string_view s) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// One data or comment line of a trajectory file.
struct TextLine {
  std::size_t number = 0;  // 1-based
  std::string_view text;   // trimmed
};

// All non-blank lines; `content` must outlive the result.
std::vector<TextLine> SplitLines(const std::string& content) {
  std::vector<TextLine> lines;
  std::size_t start = 0;
  std::size_t number = 0;
  while (start <= content.size()) {
    std::size_t end = content.find('\n', start);
    if (end == std::string::npos) end = content.size();
    ++number;
    const std::string_view text = Trim(std::string_view(content).substr(start, end - start));
    if (!text.empty()) lines.push_back({number, text});
    start = end + 1;
  }
  return lines;
}

bool IsComment(const TextLine& line) { return line.text.front() == '#'; }

// Fields of a data line: comma separated when the line has a comma (each field trimmed, empty
// fields kept so they are reported), otherwise separated by runs of spaces/tabs.
std::vector<std::string_view> SplitFields(std::string_view text, bool* comma_separated) {
  std::vector<std::string_view> fields;
  *comma_separated = text.find(',') != std::string_view::npos;
  if (*comma_separated) {
    std::size_t start = 0;
    while (true) {
      const std::size_t end = text.find(',', start);
      fields.push_back(Trim(text.substr(start, end == std::string_view::npos ? end : end - start)));
      if (end == std::string_view::npos) break;
      start = end + 1;
    }
    return fields;
  }
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < text.size() && text[i] != ' ' && text[i] != '\t') ++i;
    if (i > start) fields.push_back(text.substr(start, i - start));
  }
  return fields;
}

std::string ReadWholeFile(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    throw InputError(file, std::filesystem::exists(file, ec) ? "not a regular file"
                                                             : "trajectory file not found");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot open trajectory file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// Parses a double field; throws InputError for garbage or non-finite values.
double ParseField(std::string_view field, std::size_t column, const std::filesystem::path& file,
                  std::size_t line) {
  double value = 0.0;
  const char* first = field.data();
  const char* last = field.data() + field.size();
  if (!field.empty() && *first == '+') ++first;  // from_chars rejects a leading '+'
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (field.empty() || ec != std::errc() || ptr != last) {
    throw InputError(file, line, fmt::format("column {}: '{}' is not a number", column, field));
  }
  if (!std::isfinite(value)) {
    throw InputError(file, line, fmt::format("column {}: non-finite value '{}'", column, field));
  }
  return value;
}

std::int64_t ParseTimestamp(std::string_view field, bool nanoseconds,
                            const std::filesystem::path& file, std::size_t line) {
  if (const auto t_ns = ParseDecimalAsInt64(field, nanoseconds ? 0 : 9)) return *t_ns;
  ParseField(field, 1, file, line);  // reports garbage / non-finite text precisely
  throw InputError(file, line, fmt::format("timestamp '{}' is out of range", field));
}

// Column layout of one format.
struct Layout {
  bool nanoseconds = false;
  bool quaternion_w_first = false;
  std::string_view columns;  // for messages
};

Layout LayoutOf(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return {false, false, "t[s] x y z qx qy qz qw"};
    case TrajectoryFormat::kOrbSlam3:
      return {true, false, "t[ns] x y z qx qy qz qw"};
    case TrajectoryFormat::kEuroc:
      return {true, true, "t[ns],x,y,z,qw,qx,qy,qz[,vx,vy,vz,bgx,bgy,bgz,bax,bay,baz]"};
    case TrajectoryFormat::kAuto:
      break;
  }
  throw Error("trajectory layout requested for the 'auto' format");
}

TrajectoryFormat DetectFormat(const std::vector<TextLine>& lines,
                              const std::filesystem::path& file) {
  for (const TextLine& line : lines) {
    if (IsComment(line)) {
      // EuRoC's header: "#timestamp, p_RS_R_x [m], ..., q_RS_w [], ...".
      if (line.text.find("p_RS_R_x") != std::string_view::npos ||
          line.text.find("q_RS_w") != std::string_view::npos) {
        return TrajectoryFormat::kEuroc;
      }
      continue;
    }
    bool comma = false;
    const std::vector<std::string_view> fields = SplitFields(line.text, &comma);
    if (fields.size() == 17) return TrajectoryFormat::kEuroc;
    if (fields.size() != 8) {
      throw InputError(file, line.number,
                       fmt::format("unknown trajectory format: {} columns (expected 8 for "
                                   "tum/orbslam3/euroc or 17 for euroc ground truth)",
                                   fields.size()));
    }
    const double t = ParseField(fields[0], 1, file, line.number);
    if (std::abs(t) >= kNanosecondThreshold) {
      return comma ? TrajectoryFormat::kEuroc : TrajectoryFormat::kOrbSlam3;
    }
    return TrajectoryFormat::kTum;
  }
  throw InputError(file, "empty trajectory file (no pose lines)");
}

// Seconds with exactly 9 decimals from integer nanoseconds (exact; handles negative times).
std::string FormatSeconds(std::int64_t t_ns) {
  const bool negative = t_ns < 0;
  // Work in unsigned so that INT64_MIN does not overflow on negation.
  const std::uint64_t magnitude =
      negative ? ~static_cast<std::uint64_t>(t_ns) + 1 : static_cast<std::uint64_t>(t_ns);
  return fmt::format("{}{}.{:09d}", negative ? "-" : "", magnitude / 1000000000u,
                     magnitude % 1000000000u);
}

}  // namespace

std::vector<std::int64_t> Trajectory::Timestamps() const {
  std::vector<std::int64_t> t;
  t.reserve(poses.size());
  for (const StampedPose& p : poses) t.push_back(p.t_ns);
  return t;
}

TrajectoryFormat ParseTrajectoryFormat(std::string_view name) {
  if (name == "auto") return TrajectoryFormat::kAuto;
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "euroc") return TrajectoryFormat::kEuroc;
  if (name == "orbslam3") return TrajectoryFormat::kOrbSlam3;
  throw OptionError(
      fmt::format("unknown trajectory format '{}' (expected auto|tum|euroc|orbslam3)", name));
}

std::string_view TrajectoryFormatName(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kAuto:
      return "auto";
    case TrajectoryFormat::kTum:
      return "tum";
    case TrajectoryFormat::kEuroc:
      return "euroc";
    case TrajectoryFormat::kOrbSlam3:
      return "orbslam3";
  }
  return "?";
}

TrajectoryFormat DetectTrajectoryFormat(const std::filesystem::path& file) {
  const std::string content = ReadWholeFile(file);
  return DetectFormat(SplitLines(content), file);
}

Trajectory ReadTrajectory(const std::filesystem::path& file, TrajectoryFormat format,
                          DuplicateTimestamps duplicates) {
  const std::string content = ReadWholeFile(file);
  const std::vector<TextLine> lines = SplitLines(content);
  if (format == TrajectoryFormat::kAuto) format = DetectFormat(lines, file);
  const Layout layout = LayoutOf(format);

  Trajectory trajectory;
  trajectory.source = file;
  std::size_t expected_columns = 0;  // fixed by the first data line
  std::size_t far_from_unit = 0;
  std::size_t first_far_line = 0;
  double first_far_norm = 1.0;
  std::size_t duplicates_dropped = 0;
  std::size_t first_duplicate_line = 0;
  for (const TextLine& line : lines) {
    if (IsComment(line)) continue;
    bool comma = false;
    const std::vector<std::string_view> fields = SplitFields(line.text, &comma);
    const bool columns_ok = format == TrajectoryFormat::kEuroc
                                ? (fields.size() == 8 || fields.size() == 17)
                                : fields.size() == 8;
    if (!columns_ok || (expected_columns != 0 && fields.size() != expected_columns)) {
      throw InputError(file, line.number,
                       fmt::format("expected {} columns ({}), found {}",
                                   expected_columns != 0 ? fmt::format("{}", expected_columns)
                                   : format == TrajectoryFormat::kEuroc ? std::string("8 or 17")
                                                                        : std::string("8"),
                                   layout.columns, fields.size()));
    }
    expected_columns = fields.size();

    StampedPose stamped;
    stamped.t_ns = ParseTimestamp(fields[0], layout.nanoseconds, file, line.number);
    double v[16];
    for (std::size_t c = 1; c < fields.size(); ++c) {
      v[c - 1] = ParseField(fields[c], c + 1, file, line.number);
    }
    // Eigen's quaternion constructor takes (w, x, y, z).
    const Eigen::Quaterniond q = layout.quaternion_w_first
                                     ? Eigen::Quaterniond(v[3], v[4], v[5], v[6])
                                     : Eigen::Quaterniond(v[6], v[3], v[4], v[5]);
    // stableNorm, and q scaled by it before SO3 normalises: with components beyond ~1e154,
    // q.norm() overflowed to inf and the normalised quaternion came out zero (not a rotation).
    const double norm = q.coeffs().stableNorm();
    if (norm < kQuaternionNormMinimum) {
      throw InputError(file, line.number, "zero quaternion (not a rotation)");
    }
    if (std::abs(norm - 1.0) > kQuaternionNormWarning && far_from_unit++ == 0) {
      first_far_line = line.number;
      first_far_norm = norm;
    }
    stamped.pose = SE3d(Eigen::Quaterniond(q.coeffs() / norm), Eigen::Vector3d(v[0], v[1], v[2]));

    if (!trajectory.poses.empty() && stamped.t_ns <= trajectory.poses.back().t_ns) {
      const bool repeat = stamped.t_ns == trajectory.poses.back().t_ns;
      if (repeat && duplicates != DuplicateTimestamps::kError) {
        if (duplicates_dropped++ == 0) first_duplicate_line = line.number;
        if (duplicates == DuplicateTimestamps::kKeepFirst) continue;
      } else {
        throw InputError(
            file, line.number,
            fmt::format("timestamp {} s {} the previous one ({} s): poses must be sorted by time{}",
                        FormatSeconds(stamped.t_ns), repeat ? "repeats" : "is before",
                        FormatSeconds(trajectory.poses.back().t_ns),
                        repeat ? " without duplicates" : ""));
      }
    }
    trajectory.poses.push_back(stamped);
    if (fields.size() == 17) {
      GroundTruthExtras extras;
      extras.velocity_world = Eigen::Vector3d(v[7], v[8], v[9]);
      extras.gyro_bias = Eigen::Vector3d(v[10], v[11], v[12]);
      extras.accel_bias = Eigen::Vector3d(v[13], v[14], v[15]);
      trajectory.extras.push_back(extras);
    }
  }
  if (trajectory.poses.empty()) throw InputError(file, "empty trajectory file (no pose lines)");
  if (duplicates_dropped > 0) {
    PKSLAM_LOG_WARN("{}: {} {} line(s) repeating the previous timestamp (first at line {})",
                    file.string(), duplicates == DuplicateTimestamps::kKeepAll ? "kept" : "dropped",
                    duplicates_dropped, first_duplicate_line);
  }
  if (far_from_unit > 0) {
    PKSLAM_LOG_WARN(
        "{}: {} quaternion(s) far from unit norm (first at line {}, norm {:.4f}); "
        "normalised",
        file.string(), far_from_unit, first_far_line, first_far_norm);
  }
  PKSLAM_LOG_DEBUG("{}: {} poses ({} format)", file.string(), trajectory.size(),
                   TrajectoryFormatName(format));
  return trajectory;
}

std::string FormatTumLine(const StampedPose& p) {
  const Eigen::Vector3d& t = p.pose.translation();
  const Eigen::Quaterniond& q = p.pose.quaternion();
  return fmt::format("{} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n", FormatSeconds(p.t_ns),
                     t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
}

void WriteTrajectoryTum(const Trajectory& trajectory, const std::filesystem::path& file) {
  std::string text = kTumHeader;
  for (const StampedPose& p : trajectory.poses) text += FormatTumLine(p);
  WriteFileAtomically(file, text);
}

void WriteTrajectoryEuroc(const Trajectory& trajectory, const std::filesystem::path& file) {
  const bool extras = trajectory.has_extras();
  std::string text =
      "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],"
      "q_RS_z []";
  if (extras) {
    text +=
        ",v_RS_R_x [m s^-1],v_RS_R_y [m s^-1],v_RS_R_z [m s^-1],b_w_RS_S_x [rad s^-1],"
        "b_w_RS_S_y [rad s^-1],b_w_RS_S_z [rad s^-1],b_a_RS_S_x [m s^-2],b_a_RS_S_y [m s^-2],"
        "b_a_RS_S_z [m s^-2]";
  }
  text += '\n';
  for (std::size_t i = 0; i < trajectory.poses.size(); ++i) {
    const StampedPose& p = trajectory.poses[i];
    const Eigen::Vector3d& t = p.pose.translation();
    const Eigen::Quaterniond& q = p.pose.quaternion();
    text += fmt::format("{},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f}", p.t_ns, t.x(), t.y(),
                        t.z(), q.w(), q.x(), q.y(), q.z());
    if (extras) {
      const GroundTruthExtras& e = trajectory.extras[i];
      for (const Eigen::Vector3d* v : {&e.velocity_world, &e.gyro_bias, &e.accel_bias}) {
        text += fmt::format(",{:.9f},{:.9f},{:.9f}", v->x(), v->y(), v->z());
      }
    }
    text += '\n';
  }
  WriteFileAtomically(file, text);
}

void WriteTrajectory(const Trajectory& trajectory, const std::filesystem::path& file,
                     TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return WriteTrajectoryTum(trajectory, file);
    case TrajectoryFormat::kEuroc:
      return WriteTrajectoryEuroc(trajectory, file);
    case TrajectoryFormat::kOrbSlam3: {
      std::string text;
      for (const StampedPose& p : trajectory.poses) {
        const Eigen::Vector3d& t = p.pose.translation();
        const Eigen::Quaterniond& q = p.pose.quaternion();
        text += fmt::format("{} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n", p.t_ns, t.x(),
                            t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
      }
      return WriteFileAtomically(file, text);
    }
    case TrajectoryFormat::kAuto:
      break;
  }
  throw OptionError("a trajectory cannot be written in the 'auto' format");
}

double PathLengthMeters(const Trajectory& trajectory) {
  double length = 0.0;
  for (std::size_t i = 1; i < trajectory.poses.size(); ++i) {
    length += (trajectory.poses[i].pose.translation() - trajectory.poses[i - 1].pose.translation())
                  .norm();
  }
  return length;
}

double DurationSeconds(const Trajectory& trajectory) {
  if (trajectory.poses.size() < 2) return 0.0;
  // In 128 bits: the span of a file's timestamps can exceed int64 (pkslam eval overflowed).
  const __int128 span =
      static_cast<__int128>(trajectory.poses.back().t_ns) - trajectory.poses.front().t_ns;
  return static_cast<double>(span) * 1e-9;
}

std::optional<std::int64_t> ParseDecimalAsInt64(std::string_view text, int decimal_shift) {
  std::size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) negative = text[i++] == '-';
  std::string digits;  // all mantissa digits, decimal point removed
  int fraction_digits = 0;
  bool seen_point = false;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c >= '0' && c <= '9') {
      digits.push_back(c);
      if (seen_point) ++fraction_digits;
    } else if (c == '.' && !seen_point) {
      seen_point = true;
    } else {
      break;
    }
  }
  if (digits.empty()) return std::nullopt;
  int exponent = 0;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    bool exponent_negative = false;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) exponent_negative = text[i++] == '-';
    const std::size_t exponent_start = i;
    for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i) {
      if (exponent < 100000) exponent = exponent * 10 + (text[i] - '0');
    }
    if (i == exponent_start) return std::nullopt;
    if (exponent_negative) exponent = -exponent;
  }
  if (i != text.size()) return std::nullopt;

  // value = digits * 10^shift.
  const long shift = static_cast<long>(exponent) + decimal_shift - fraction_digits;
  bool round_up = false;
  if (shift < 0) {
    const long drop = -shift;
    if (drop > static_cast<long>(digits.size())) {
      digits = "0";
    } else {
      const std::size_t keep = digits.size() - static_cast<std::size_t>(drop);
      round_up = digits[keep] >= '5';
      digits.resize(keep);
      if (digits.empty()) digits = "0";
    }
  } else {
    if (shift > 40) {
      if (digits.find_first_not_of('0') == std::string::npos) return 0;
      return std::nullopt;
    }
    digits.append(static_cast<std::size_t>(shift), '0');
  }
  // Accumulate with overflow checks (|value| <= 2^63 for negatives, 2^63 - 1 otherwise).
  const unsigned __int128 limit =
      static_cast<unsigned __int128>(std::numeric_limits<std::int64_t>::max()) +
      (negative ? 1u : 0u);
  unsigned __int128 value = 0;
  for (const char c : digits) {
    value = value * 10 + static_cast<unsigned>(c - '0');
    if (value > limit) return std::nullopt;
  }
  if (round_up && ++value > limit) return std::nullopt;
  if (negative) return static_cast<std::int64_t>(-static_cast<__int128>(value));
  return static_cast<std::int64_t>(value);
}

std::optional<std::filesystem::path> FindDatasetGroundTruth(const std::filesystem::path& dataset) {
  for (const std::filesystem::path& f : {dataset / "mav0/state_groundtruth_estimate0/data.csv",
                                         dataset / "mav0/mocap0/data.csv",  // TUM-VI
                                         dataset / "groundtruth.txt"}) {
    if (std::filesystem::exists(f)) return f;
  }
  return std::nullopt;
}

}  // namespace pkslam
