// pkslam vocab {train, convert, info}: the place-recognition vocabulary (core/bow).
#include <fmt/format.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "core/bow/training_data.h"
#include "core/bow/vocabulary.h"
#include "core/util/error.h"
#include "core/util/log.h"

namespace pkslam::apps {
namespace {

namespace fs = std::filesystem;

struct TrainArgs {
  std::vector<std::string> image_dirs;
  std::string out;
  std::size_t max_images = 0;
  bool quiet = false;
  TrainingFeatureOptions features;
  VocabularyTrainOptions train;
};

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void CheckOutputExtension(const fs::path& out) {
  const std::string ext = out.extension().string();
  if (ext != ".txt" && ext != ".bin" && ext != ".pkvoc") {
    throw OptionError(
        fmt::format("output '{}': extension must be .txt (DBoW2 text) or .bin / .pkvoc (binary)",
                    out.string()));
  }
}

void RunTrain(const TrainArgs& args) {
  args.features.Check();
  VocabularyTrainOptions options = args.train;
  options.quiet = args.quiet;
  options.Check();
  const fs::path out = args.out;
  CheckOutputExtension(out);  // fail before hours of work, not after

  const auto start = std::chrono::steady_clock::now();
  const std::vector<fs::path> dirs(args.image_dirs.begin(), args.image_dirs.end());
  const std::vector<fs::path> images = ListTrainingImages(dirs, args.max_images);
  PKSLAM_LOG_INFO("vocab train: {} images from {} director{}", images.size(), dirs.size(),
                  dirs.size() == 1 ? "y" : "ies");
  const auto descriptors = ExtractTrainingSet(images, args.features, args.quiet);
  std::size_t total = 0;
  for (const auto& d : descriptors) total += d.size();
  const double t_features = SecondsSince(start);

  const auto train_start = std::chrono::steady_clock::now();
  const Vocabulary vocabulary = Vocabulary::Train(descriptors, options);
  const double t_train = SecondsSince(train_start);
  vocabulary.Save(out);
  PKSLAM_LOG_INFO(
      "vocab train: {} words, {} nodes, depth {} from {} descriptors; features {:.1f} s, "
      "clustering + weights {:.1f} s; wrote {} ({:.1f} MB)",
      vocabulary.word_count(), vocabulary.node_count(), vocabulary.depth(), total, t_features,
      t_train, out.string(), static_cast<double>(fs::file_size(out)) / 1e6);
}

void RunConvert(const std::string& in, const std::string& out) {
  CheckOutputExtension(out);
  const auto start = std::chrono::steady_clock::now();
  const Vocabulary vocabulary = Vocabulary::Load(in);
  const double t_load = SecondsSince(start);
  vocabulary.Save(out);
  PKSLAM_LOG_INFO("vocab convert: {} ({} words, loaded in {:.2f} s) -> {} ({:.1f} MB)", in,
                  vocabulary.word_count(), t_load, out,
                  static_cast<double>(fs::file_size(out)) / 1e6);
}

void RunInfo(const std::string& file) {
  const auto start = std::chrono::steady_clock::now();
  const bool binary = IsBinaryVocabularyFile(file);
  const Vocabulary v = Vocabulary::Load(file);
  const double t_load = SecondsSince(start);
  std::string text;
  text += fmt::format("file        {}\n", file);
  text += fmt::format("format      {}\n", binary ? "pkslam binary" : "DBoW2 text");
  text += fmt::format("size        {} bytes ({:.1f} MB)\n", fs::file_size(file),
                      static_cast<double>(fs::file_size(file)) / 1e6);
  text += fmt::format("load time   {:.3f} s\n", t_load);
  text += fmt::format("k           {}\n", v.branching());
  text += fmt::format("L           {}\n", v.levels());
  text +=
      fmt::format("scoring     {} ({})\n", ScoringName(v.scoring()), static_cast<int>(v.scoring()));
  text += fmt::format("weighting   {} ({})\n", WeightingName(v.weighting()),
                      static_cast<int>(v.weighting()));
  text += fmt::format("nodes       {} (with the root)\n", v.node_count());
  text += fmt::format("words       {}\n", v.word_count());
  text += fmt::format("depth       {} (deepest word)\n", v.depth());
  std::size_t zero_weight = 0;
  for (WordId w = 0; w < v.word_count(); ++w) zero_weight += v.WordWeight(w) <= 0.0 ? 1 : 0;
  text += fmt::format("zero-weight {} words (ignored by transform)\n", zero_weight);
  text += fmt::format("direct index level (default, from root) {}\n",
                      v.DirectIndexLevel(Vocabulary::kDefaultDirectIndexLevel));
  text += "level       nodes       words\n";
  const auto nodes = v.NodesPerLevel();
  const auto words = v.WordsPerLevel();
  for (std::size_t l = 0; l < nodes.size(); ++l) {
    text += fmt::format("{:5} {:11} {:11}\n", l, nodes[l], words[l]);
  }
  fmt::print("{}", text);
}

}  // namespace

void RegisterVocabCommand(CLI::App& app) {
  auto* vocab = app.add_subcommand(
      "vocab", "Place-recognition vocabulary (bag of binary words): train, convert, info");
  vocab->require_subcommand(1);

  auto args = std::make_shared<TrainArgs>();
  auto* train = vocab->add_subcommand(
      "train", "Train a k-ary vocabulary (hierarchical k-means++, TF-IDF) on ORB descriptors");
  train
      ->add_option("--images", args->image_dirs,
                   "Image directories (searched recursively for png/jpg/pgm/...)")
      ->required()
      ->check(CLI::ExistingDirectory);
  train->add_option("--out", args->out, "Output file: .txt (DBoW2 text) or .bin/.pkvoc")
      ->required();
  train->add_option("--k", args->train.branching, "Branching factor")
      ->check(CLI::Range(2, 255))
      ->capture_default_str();
  train->add_option("--L", args->train.levels, "Depth (levels below the root)")
      ->check(CLI::Range(1, 32))
      ->capture_default_str();
  train
      ->add_option("--max-images", args->max_images,
                   "Use at most this many images, evenly spaced (0 = all)")
      ->capture_default_str();
  train->add_option("--features", args->features.max_features, "ORB features per image")
      ->capture_default_str();
  train->add_option("--seed", args->train.seed, "k-means++ seed (same seed, same vocabulary)")
      ->capture_default_str();
  train
      ->add_option("--max-iterations", args->train.max_iterations,
                   "Lloyd iterations per node at most")
      ->capture_default_str();
  train->add_flag("--quiet", args->quiet, "No progress bars");
  train->callback([args] { RunTrain(*args); });

  auto paths = std::make_shared<std::pair<std::string, std::string>>();
  auto* convert = vocab->add_subcommand(
      "convert",
      "Convert by extension: IN/OUT .txt = DBoW2 text (ORBvoc.txt), .bin/.pkvoc = binary");
  convert->add_option("IN", paths->first, "Input vocabulary (either format)")
      ->required()
      ->check(CLI::ExistingFile);
  convert->add_option("OUT", paths->second, "Output vocabulary (.txt, .bin or .pkvoc)")->required();
  convert->callback([paths] { RunConvert(paths->first, paths->second); });

  auto info_file = std::make_shared<std::string>();
  auto* info = vocab->add_subcommand(
      "info", "Print k, L, node and word counts, weighting, scoring, depth histogram, size");
  info->add_option("FILE", *info_file, "Vocabulary (either format)")
      ->required()
      ->check(CLI::ExistingFile);
  info->callback([info_file] { RunInfo(*info_file); });
}

}  // namespace pkslam::apps
