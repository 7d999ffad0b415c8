#include "io/dataset_fingerprint.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <vector>

#include "core/util/error.h"
#include "core/util/log.h"
#include "io/euroc_dataset.h"
#include "io/tum_rgbd_dataset.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

class Fnv1a64 {
 public:
  void Add(std::string_view bytes) {
    for (const char c : bytes) {
      hash_ ^= static_cast<unsigned char>(c);
      hash_ *= 0x100000001b3ULL;
    }
  }
  void AddFile(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, "cannot read (for the dataset fingerprint)");
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    Add(bytes);
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

}  // namespace

std::string DatasetFingerprint(const ImageStream& frames) {
  Fnv1a64 hash;
  hash.AddFile(frames.list_file);
  const auto& images = frames.images;
  if (!images.empty()) {
    for (const std::size_t i : {std::size_t{0}, images.size() / 2, images.size() - 1}) {
      hash.AddFile(images[i].path);
    }
  }
  return fmt::format("{:016x}", hash.value());
}

std::string DatasetFingerprint(const fs::path& dataset) {
  if (EurocDataset::LooksLikeEuroc(dataset)) {
    EurocOptions options;
    options.read_imu = false;
    options.read_ground_truth = false;
    return DatasetFingerprint(EurocDataset::Open(dataset, options).cam0());
  }
  if (TumRgbdDataset::LooksLikeTumRgbd(dataset)) {
    return DatasetFingerprint(TumRgbdDataset::Open(dataset).rgb());
  }
  throw InputError(dataset, "not a EuRoC or TUM RGB-D dataset");
}

void RequireRunOfDataset(const fs::path& run_dir, const fs::path& dataset) {
  const fs::path stats = run_dir / "stats.json";
  if (!fs::exists(stats)) {
    PKSLAM_LOG_WARN("{}: missing: cannot check that {} is the run's dataset", stats.string(),
                    dataset.string());
    return;
  }
  std::string recorded;
  std::string recorded_path;
  try {
    // stats.json is plain JSON, which yaml-cpp reads as YAML flow style.
    const YAML::Node root = YAML::LoadFile(stats.string());
    if (root["dataset_fingerprint"]) recorded = root["dataset_fingerprint"].as<std::string>();
    if (root["dataset"]) recorded_path = root["dataset"].as<std::string>();
  } catch (const YAML::Exception& e) {
    throw InputError(stats, "cannot read the run's stats.json: " + e.msg);
  }
  if (recorded.empty()) {
    PKSLAM_LOG_WARN(
        "{}: no dataset_fingerprint (an older run): cannot check that {} is the "
        "run's dataset",
        stats.string(), dataset.string());
    return;
  }
  const std::string actual = DatasetFingerprint(dataset);
  if (actual != recorded) {
    throw InputError(dataset, fmt::format("not the dataset run {} was made from (its images "
                                          "differ: fingerprint {} here, {} in the run, whose "
                                          "dataset was {})",
                                          run_dir.string(), actual, recorded, recorded_path));
  }
}

}  // namespace pkslam
