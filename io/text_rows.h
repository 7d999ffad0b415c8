// Line-oriented reading of dataset text files (EuRoC csv, TUM whitespace lists) with 1-based
// line numbers, and exact parsing of the fields they hold. Timestamps never pass through a
// double: EuRoC ns are parsed as int64, TUM decimal seconds digit by digit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

namespace pkslam {

enum class FieldSeparator {
  kComma,      // EuRoC csv: fields separated by ',', surrounding blanks trimmed
  kWhitespace  // TUM lists: fields separated by runs of spaces/tabs (a ',' also separates)
};

// One data row handed to a ForEachDataRow callback. The views are valid only during the call.
struct TextRow {
  std::size_t line = 0;  // 1-based line number in the file
  std::vector<std::string_view> fields;
};

// Calls `fn` for every data row of `file`: blank lines and lines whose first non-blank
// character is '#' are skipped; '\r' line ends are accepted. Returns the number of data rows.
// Throws InputError(file) if the file cannot be opened. `fn` may throw (e.g. InputError).
std::size_t ForEachDataRow(const std::filesystem::path& file, FieldSeparator separator,
                           const std::function<void(const TextRow&)>& fn);

// Exact parse of a whole field; nullopt if the text is not entirely a valid number.
std::optional<std::int64_t> ParseInt64(std::string_view text);
// Finite doubles only (std::from_chars: correctly rounded, locale independent).
std::optional<double> ParseDouble(std::string_view text);
// Decimal seconds ("1305031102.175304", "-0.5", "12") to integer nanoseconds, exactly: the
// integer and fraction digits are combined as integers. Digits beyond the 9th decimal are
// rounded half away from zero. No exponents. nullopt when malformed or out of int64 range.
std::optional<std::int64_t> ParseDecimalSecondsToNs(std::string_view text);

// The same, throwing InputError(file, line, "<what>: '<text>' is not ...") on failure.
std::int64_t Int64Field(std::string_view text, const std::filesystem::path& file, std::size_t line,
                        std::string_view what);
double DoubleField(std::string_view text, const std::filesystem::path& file, std::size_t line,
                   std::string_view what);
std::int64_t SecondsFieldToNs(std::string_view text, const std::filesystem::path& file,
                              std::size_t line, std::string_view what);

// Throws InputError(file, line) unless the row has exactly `expected` fields.
void RequireFieldCount(const TextRow& row, std::size_t expected, const std::filesystem::path& file,
                       std::string_view layout);

// Throws InputError(file, line) unless 0 <= t_ns and t_ns > previous_t_ns (duplicates and
// negative stamps are errors too).
// `previous_t_ns` is nullopt for the first row.
void RequireIncreasing(std::optional<std::int64_t> previous_t_ns, std::int64_t t_ns,
                       const std::filesystem::path& file, std::size_t line);

}  // namespace pkslam
