// Vocabulary speed: transform of one keyframe's descriptors, loading a ~1M-word vocabulary,
// and training. Run: build/benchmarks/pkslam_core_benchmark --benchmark_filter=Vocabulary
#include <benchmark/benchmark.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <vector>

#include "core/bow/bow_test_utils.h"
#include "core/bow/training_data.h"
#include "core/bow/vocabulary.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

// 1200 ORB descriptors of a real EuRoC frame (cv::ORB, 8 levels, 1.2) or, without the shared
// data, random ones.
std::vector<Descriptor> KeyframeDescriptors() {
  if (const auto shared = pkslam::testing::SharedDataDir()) {
    const fs::path dir = *shared / "euroc/V1_01_easy_static/mav0/cam0/data";
    if (fs::is_directory(dir)) {
      const auto images = ListTrainingImages({dir}, 1);
      TrainingFeatureOptions options;
      options.max_features = 1200;
      auto d = ExtractTrainingDescriptors(cv::imread(images.front().string(), cv::IMREAD_GRAYSCALE),
                                          options);
      if (!d.empty()) return d;
    }
  }
  std::mt19937_64 rng(5);
  std::vector<Descriptor> d;
  for (int i = 0; i < 1200; ++i) d.push_back(pkslam::testing::RandomDescriptor(rng));
  return d;
}

void RunTransform(benchmark::State& state, const Vocabulary& vocabulary) {
  const std::vector<Descriptor> descriptors = KeyframeDescriptors();
  BowVector bow;
  FeatureVector features;
  for (auto _ : state) {
    vocabulary.Transform(descriptors, &bow, &features, Vocabulary::kDefaultDirectIndexLevel);
    benchmark::DoNotOptimize(bow);
    benchmark::DoNotOptimize(features);
  }
  state.counters["descriptors"] = static_cast<double>(descriptors.size());
  state.counters["words"] = static_cast<double>(vocabulary.word_count());
  state.counters["bow_nnz"] = static_cast<double>(bow.size());
  state.counters["fv_groups"] = static_cast<double>(features.size());
}

// Full k=10, L=6 tree (1,111,110 nodes, 10^6 words) with random centres: the memory footprint
// and access pattern of ORBvoc.txt.
void BM_VocabularyTransform1200_K10L6(benchmark::State& state) {
  RunTransform(state, pkslam::testing::MakeRandomVocabulary(10, 6, 1));
}
BENCHMARK(BM_VocabularyTransform1200_K10L6)->Unit(benchmark::kMicrosecond);

// The vocabulary shipped in Vocabulary/ (trained), when present.
void BM_VocabularyTransform1200_Shipped(benchmark::State& state) {
  const fs::path file = fs::path(PKSLAM_SOURCE_DIR) / "Vocabulary/pkslam_orb_k10_L6.bin";
  if (!fs::exists(file)) {
    state.SkipWithError("Vocabulary/pkslam_orb_k10_L6.bin not found");
    return;
  }
  RunTransform(state, Vocabulary::Load(file));
}
BENCHMARK(BM_VocabularyTransform1200_Shipped)->Unit(benchmark::kMicrosecond);

class VocabularyFileFixture : public benchmark::Fixture {
 public:
  void SetUp(const benchmark::State&) override {
    dir_ = pkslam::testing::MakeTempDir("pkslam_vocab_bench");
    const Vocabulary v = pkslam::testing::MakeRandomVocabulary(10, 6, 2);
    v.SaveBinary(dir_ / "voc.pkvoc");
    v.SaveText(dir_ / "voc.txt");
  }
  void TearDown(const benchmark::State&) override { fs::remove_all(dir_); }

 protected:
  fs::path dir_;
};

BENCHMARK_DEFINE_F(VocabularyFileFixture, BM_VocabularyLoadBinary1M)(benchmark::State& state) {
  for (auto _ : state) {
    const Vocabulary v = Vocabulary::LoadBinary(dir_ / "voc.pkvoc");
    benchmark::DoNotOptimize(v.word_count());
  }
  state.counters["MB"] = static_cast<double>(fs::file_size(dir_ / "voc.pkvoc")) / 1e6;
}
BENCHMARK_REGISTER_F(VocabularyFileFixture, BM_VocabularyLoadBinary1M)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

BENCHMARK_DEFINE_F(VocabularyFileFixture, BM_VocabularyLoadText1M)(benchmark::State& state) {
  for (auto _ : state) {
    const Vocabulary v = Vocabulary::LoadText(dir_ / "voc.txt");
    benchmark::DoNotOptimize(v.word_count());
  }
  state.counters["MB"] = static_cast<double>(fs::file_size(dir_ / "voc.txt")) / 1e6;
}
BENCHMARK_REGISTER_F(VocabularyFileFixture, BM_VocabularyLoadText1M)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

// k=10, L=6 training on uniformly random descriptors (the slowest case for k-means: no
// structure to converge to), split into images of 1000. Arg: descriptor count.
void BM_VocabularyTrainK10L6(benchmark::State& state) {
  std::mt19937_64 rng(9);
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<std::vector<Descriptor>> images((n + 999) / 1000);
  for (std::size_t i = 0; i < n; ++i)
    images[i / 1000].push_back(pkslam::testing::RandomDescriptor(rng));
  VocabularyTrainOptions options;
  options.quiet = true;
  std::size_t words = 0;
  for (auto _ : state) {
    words = Vocabulary::Train(images, options).word_count();
  }
  state.counters["words"] = static_cast<double>(words);
}
BENCHMARK(BM_VocabularyTrainK10L6)
    ->Arg(200000)
    ->Arg(3000000)
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

// k=10, L=6 training on real ORB structure at scale: the descriptors of the EuRoC static slice
// and the opencv-doc photos (~0.3 M), each repeated with 0-15 random bit flips up to the
// requested count. Arg: descriptor count.
void BM_VocabularyTrainK10L6_RealPerturbed(benchmark::State& state) {
  std::vector<fs::path> dirs;
  if (const auto shared = pkslam::testing::SharedDataDir()) {
    dirs.push_back(*shared / "euroc/V1_01_easy_static/mav0");
  }
  dirs.push_back("/usr/share/doc/opencv-doc/examples/data");
  std::erase_if(dirs, [](const fs::path& d) { return !fs::is_directory(d); });
  if (dirs.empty()) {
    state.SkipWithError("no real images (shared data, opencv-doc)");
    return;
  }
  TrainingFeatureOptions features;
  features.max_features = 1200;
  const auto real = ExtractTrainingSet(ListTrainingImages(dirs, 0), features, true);
  const auto n = static_cast<std::size_t>(state.range(0));
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> flips(0, 15);
  std::vector<std::vector<Descriptor>> images;
  std::size_t count = 0;
  for (std::size_t copy = 0; count < n; ++copy) {
    for (const auto& image : real) {
      images.emplace_back();
      for (const Descriptor& d : image) {
        if (count == n) break;
        images.back().push_back(copy == 0 ? d : pkslam::testing::FlipBits(d, flips(rng), rng));
        ++count;
      }
    }
  }
  VocabularyTrainOptions options;
  options.quiet = true;
  std::size_t words = 0;
  for (auto _ : state) {
    words = Vocabulary::Train(images, options).word_count();
  }
  state.counters["words"] = static_cast<double>(words);
  state.counters["images"] = static_cast<double>(images.size());
}
BENCHMARK(BM_VocabularyTrainK10L6_RealPerturbed)
    ->Arg(3000000)
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

}  // namespace
}  // namespace pkslam
