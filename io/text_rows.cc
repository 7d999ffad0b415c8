#include "io/text_rows.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <string>

#include "core/util/error.h"

namespace pkslam {
namespace {

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view Trim(std::string_view s) {
  while (!s.empty() && IsBlank(s.front())) s.remove_prefix(1);
  while (!s.empty() && IsBlank(s.back())) s.remove_suffix(1);
  return s;
}

void SplitFields(std::string_view line, FieldSeparator separator,
                 std::vector<std::string_view>* fields) {
  fields->clear();
  if (separator == FieldSeparator::kComma) {
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      if (comma == std::string_view::npos) {
        fields->push_back(Trim(line.substr(start)));
        return;
      }
      fields->push_back(Trim(line.substr(start, comma - start)));
      start = comma + 1;
    }
  }
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (IsBlank(line[i]) || line[i] == ',')) ++i;
    const std::size_t begin = i;
    while (i < line.size() && !IsBlank(line[i]) && line[i] != ',') ++i;
    if (i > begin) fields->push_back(line.substr(begin, i - begin));
  }
}

// Shortens long field texts in error messages.
std::string Quote(std::string_view text) {
  constexpr std::size_t kMax = 40;
  if (text.size() <= kMax) return fmt::format("'{}'", text);
  return fmt::format("'{}...'", text.substr(0, kMax));
}

}  // namespace

std::size_t ForEachDataRow(const std::filesystem::path& file, FieldSeparator separator,
                           const std::function<void(const TextRow&)>& fn) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    throw InputError(
        file, std::filesystem::exists(file) ? "cannot open file for reading" : "file not found");
  }
  std::string line;
  TextRow row;
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    ++row.line;
    const std::string_view trimmed = Trim(line);
    if (trimmed.empty() || trimmed.front() == '#') continue;
    SplitFields(trimmed, separator, &row.fields);
    fn(row);
    ++rows;
  }
  if (in.bad()) throw InputError(file, row.line, "read error");
  return rows;
}

std::optional<std::int64_t> ParseInt64(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

std::optional<double> ParseDouble(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty() ||
      !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

std::optional<std::int64_t> ParseDecimalSecondsToNs(std::string_view text) {
  bool negative = false;
  if (!text.empty() && (text.front() == '-' || text.front() == '+')) {
    negative = text.front() == '-';
    text.remove_prefix(1);
  }
  const std::size_t dot = text.find('.');
  const std::string_view int_part = text.substr(0, dot);
  const std::string_view frac_part =
      dot == std::string_view::npos ? std::string_view() : text.substr(dot + 1);
  if (int_part.empty() && frac_part.empty()) return std::nullopt;
  const auto all_digits = [](std::string_view s) {
    for (char c : s) {
      if (c < '0' || c > '9') return false;
    }
    return true;
  };
  if (!all_digits(int_part) || !all_digits(frac_part)) return std::nullopt;

  std::int64_t ns = 0;
  for (char c : int_part) {
    if (__builtin_mul_overflow(ns, 10, &ns) || __builtin_add_overflow(ns, c - '0', &ns)) {
      return std::nullopt;
    }
  }
  if (__builtin_mul_overflow(ns, std::int64_t{1'000'000'000}, &ns)) return std::nullopt;
  std::int64_t frac = 0;
  for (std::size_t i = 0; i < 9; ++i) {
    frac = frac * 10 + (i < frac_part.size() ? frac_part[i] - '0' : 0);
  }
  if (frac_part.size() > 9 && frac_part[9] >= '5') ++frac;  // half away from zero
  if (__builtin_add_overflow(ns, frac, &ns)) return std::nullopt;
  return negative ? -ns : ns;
}

std::int64_t Int64Field(std::string_view text, const std::filesystem::path& file, std::size_t line,
                        std::string_view what) {
  if (const auto v = ParseInt64(text)) return *v;
  throw InputError(file, line, fmt::format("{}: {} is not an integer", what, Quote(text)));
}

double DoubleField(std::string_view text, const std::filesystem::path& file, std::size_t line,
                   std::string_view what) {
  if (const auto v = ParseDouble(text)) return *v;
  throw InputError(file, line, fmt::format("{}: {} is not a finite number", what, Quote(text)));
}

std::int64_t SecondsFieldToNs(std::string_view text, const std::filesystem::path& file,
                              std::size_t line, std::string_view what) {
  if (const auto v = ParseDecimalSecondsToNs(text)) return *v;
  throw InputError(file, line,
                   fmt::format("{}: {} is not a decimal time in seconds", what, Quote(text)));
}

void RequireFieldCount(const TextRow& row, std::size_t expected, const std::filesystem::path& file,
                       std::string_view layout) {
  if (row.fields.size() != expected) {
    throw InputError(
        file, row.line,
        fmt::format("expected {} fields ({}), found {}", expected, layout, row.fields.size()));
  }
}

void RequireIncreasing(std::optional<std::int64_t> previous_t_ns, std::int64_t t_ns,
                       const std::filesystem::path& file, std::size_t line) {
  // A negative stamp (a sign error, a clock before its epoch) made "1.6e9 s of data" of a
  // 3 s sequence and a realtime run that slept for it.
  if (t_ns < 0) {
    throw InputError(
        file, line,
        fmt::format("negative timestamp {} (sensor timestamps count from an epoch)", t_ns));
  }
  if (!previous_t_ns || t_ns > *previous_t_ns) return;
  throw InputError(
      file, line,
      fmt::format("timestamp {} {} the previous row's {} (timestamps must be "
                  "strictly increasing)",
                  t_ns, t_ns == *previous_t_ns ? "duplicates" : "is before", *previous_t_ns));
}

}  // namespace pkslam
