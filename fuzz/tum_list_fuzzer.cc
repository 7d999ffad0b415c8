// Fuzz target: the TUM RGB-D reader (io/tum_rgbd_dataset.h). The input holds rgb.txt,
// depth.txt and groundtruth.txt separated by lines "=====" (depth.txt defaults to rgb.txt, no
// second separator means no ground truth); TumRgbdDataset::Open reads them from a scratch
// folder. The lists are also read and associated directly, whether or not their image files
// exist. Bad input must end in InputError; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/util/error.h"
#include "fuzz/fuzz_support.h"
#include "io/tum_rgbd_dataset.h"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  pkslam::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pkslam;
  namespace fs = std::filesystem;
  const std::vector<std::string_view> parts =
      fuzz::SplitInput(std::string_view(reinterpret_cast<const char*>(data), size), "\n=====\n", 3);
  const fs::path root = fuzz::ScratchDir() / "tum";
  std::error_code ec;
  fs::create_directories(root, ec);
  fuzz::WriteScratchFile("tum/rgb.txt", parts[0]);
  fuzz::WriteScratchFile("tum/depth.txt", parts.size() > 1 ? parts[1] : parts[0]);
  const fs::path ground_truth = root / "groundtruth.txt";
  if (parts.size() > 2) {
    fuzz::WriteScratchFile("tum/groundtruth.txt", parts[2]);
  } else {
    fs::remove(ground_truth, ec);
  }

  try {
    TumRgbdDataset::Open(root);
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  // Open associates only listed files that exist (few do here): associate the lists as read,
  // with the default window and the widest the options allow.
  try {
    std::vector<std::int64_t> rgb;
    std::vector<std::int64_t> depth;
    for (const ImageEntry& e : ReadTumImageList(root / "rgb.txt")) rgb.push_back(e.t_ns);
    for (const ImageEntry& e : ReadTumImageList(root / "depth.txt")) depth.push_back(e.t_ns);
    for (const std::int64_t window_ns : {std::int64_t{20'000'000}, std::int64_t{9'999'999'999}}) {
      for (const auto& [i, j] : AssociateTimestamps(rgb, depth, window_ns)) {
        if (i >= rgb.size() || j >= depth.size()) fuzz::Finding("association index out of range");
      }
    }
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  // On its own too: Open stops at the first bad list.
  if (parts.size() > 2) {
    try {
      ReadTumGroundTruth(ground_truth);
    } catch (const InputError& e) {
      fuzz::Rejected(e);
    }
  }
  return 0;
}
