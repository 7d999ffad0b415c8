// Outputs never overwrite or delete inputs, nor files pkslam did not make (docs/robustness.md
// "Outputs"). Checked before anything is written.
#pragma once

#include <filesystem>
#include <string_view>

namespace pkslam {

// Throws OptionError when `output` (a file or folder a command will write, given by `flag`) is
// the input `input` (given by `input_flag`), or is a file that already exists inside an input
// folder (writing it would change the input: `dense --out` onto one of the dataset's images). New
// files and folders inside an input folder are allowed. Paths are compared after resolving
// symbolic links and "..", so a relative and an absolute spelling of one place meet.
void CheckOutputIsNotInput(const std::filesystem::path& output, std::string_view flag,
                           const std::filesystem::path& input, std::string_view input_flag);

// A folder pkslam made and may clear again carries this (empty) file.
inline constexpr const char* kOwnedFolderMarker = ".pkslam-output";

// Creates `dir` (and parents) with the marker in it.
void CreateOwnedDirectory(const std::filesystem::path& dir);

// Throws OptionError unless `dir` may be cleared: absent, empty, holding kOwnedFolderMarker, or
// holding `signature` (a file only pkslam writes there: folders made before the marker existed).
void CheckOwnedDirectory(const std::filesystem::path& dir, std::string_view signature = {});

// CheckOwnedDirectory, then deletes `dir` with everything in it.
void RemoveOwnedDirectory(const std::filesystem::path& dir, std::string_view signature = {});

}  // namespace pkslam
