// A dataset's identity for checking that later commands (`dense`, `export-colmap`) get the
// dataset a run was made from: given another one with the same timestamps (two renders of the
// simulator, two recordings with the same frame list) they built plausible-looking clouds
// from the wrong images. The fingerprint hashes the frame list and the bytes of three of its
// images (first, middle, last), so it survives moving or copying the dataset but not changing
// its images.
#pragma once

#include <filesystem>
#include <string>

#include "io/dataset_common.h"

namespace pkslam {

// 16 hex digits (FNV-1a 64). EuRoC: mav0/cam0/data.csv and its images; TUM RGB-D: rgb.txt and
// its images. Throws InputError when the dataset has neither layout.
std::string DatasetFingerprint(const std::filesystem::path& dataset);
// The same from a dataset already open: its cam0 (EuRoC) or rgb (TUM RGB-D) stream.
std::string DatasetFingerprint(const ImageStream& frames);

// Throws InputError naming `dataset` when RUN_DIR/stats.json records the fingerprint of
// another dataset. Runs without one (made before it was recorded, or without stats.json) pass
// with a warning.
void RequireRunOfDataset(const std::filesystem::path& run_dir,
                         const std::filesystem::path& dataset);

}  // namespace pkslam
