#include "core/util/output_guard.h"

#include <fmt/format.h>

#include <fstream>
#include <system_error>

#include "core/util/error.h"

namespace pkslam {
namespace fs = std::filesystem;
namespace {

// The place a path names, for comparison (the path itself need not exist yet).
fs::path Resolved(const fs::path& p) {
  std::error_code ec;
  fs::path r = fs::weakly_canonical(fs::absolute(p, ec), ec);
  return ec ? fs::absolute(p).lexically_normal() : r;
}

// True when `inner` is `outer` or lies below it (whole components: /a/bc is not within /a/b).
bool IsWithin(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (o->empty()) continue;  // a trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

}  // namespace

void CheckOutputIsNotInput(const fs::path& output, std::string_view flag, const fs::path& input,
                           std::string_view input_flag) {
  if (output.empty() || input.empty()) return;
  const fs::path out = Resolved(output);
  const fs::path in = Resolved(input);
  std::error_code ec;
  const bool input_is_file = fs::is_regular_file(in, ec);
  if (out == in) {
    throw OptionError(fmt::format("{} {} is the input {} {}: pkslam never overwrites its input",
                                  flag, output.string(), input_flag, input.string()));
  }
  // A new file or folder inside an input folder adds to it and is allowed (`--out DATASET/run`);
  // writing over a file that is already there would change the input.
  if (!input_is_file && IsWithin(out, in) && fs::is_regular_file(out, ec)) {
    throw OptionError(fmt::format(
        "{} {} would overwrite a file of the input {} {}: pkslam never changes its input; "
        "choose another output",
        flag, output.string(), input_flag, input.string()));
  }
}

void CreateOwnedDirectory(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw OutputError(dir, ec.message());
  std::ofstream marker(dir / kOwnedFolderMarker);
  if (!marker) throw OutputError(dir / kOwnedFolderMarker, "cannot create");
}

void CheckOwnedDirectory(const fs::path& dir, std::string_view signature) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) return;
  if (!fs::is_directory(dir, ec)) {
    throw OptionError(fmt::format(
        "{} is in the way: pkslam writes a folder there and never deletes a file it did not make",
        dir.string()));
  }
  if (fs::is_empty(dir, ec) || fs::exists(dir / kOwnedFolderMarker, ec)) return;
  if (!signature.empty() && fs::exists(dir / std::string(signature), ec)) return;
  throw OptionError(fmt::format(
      "{} exists and was not made by pkslam: it would be replaced, so pkslam stops (move it, or "
      "choose another output folder)",
      dir.string()));
}

void RemoveOwnedDirectory(const fs::path& dir, std::string_view signature) {
  CheckOwnedDirectory(dir, signature);
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (ec) throw OutputError(dir, ec.message());
}

}  // namespace pkslam
