// Vocabulary training: hierarchical k-means++ (DBoW2's HKmeans) over all training descriptors,
// then word weights from the training images' document frequencies.
//
// Threads: sibling subtrees are clustered as independent TBB tasks (and large nodes split
// their assignment step). Each task owns its node and a disjoint slice of the shared
// descriptor array; the only shared mutable state is the atomic progress counter. The calling
// thread only draws the progress bar. Every node's seed derives from its path in the tree, so
// the result does not depend on scheduling.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "core/bow/binary_kmeans.h"
#include "core/bow/vocabulary.h"
#include "core/bow/vocabulary_internal.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/progress.h"

namespace pkslam {
namespace {

struct TrainNode {
  Descriptor centre;
  std::vector<TrainNode> children;
};

struct TreeBuilder {
  const VocabularyTrainOptions& options;
  std::vector<Descriptor>& points;  // reordered in place: each node's points are contiguous
  std::atomic<std::size_t>& progress;
  std::atomic<std::size_t>& clustered_nodes;    // nodes split by k-means (statistics)
  std::atomic<std::size_t>& unconverged_nodes;  // of which stopped by max_iterations
  std::atomic<std::size_t>& iterations;         // Lloyd iterations over all nodes

  // Clusters points [begin, end) of `node` (at `level`) and recurses into the children.
  void Build(TrainNode& node, std::size_t begin, std::size_t end, int level,
             std::uint64_t seed) const {
    const std::size_t n = end - begin;
    const auto remaining = static_cast<std::size_t>(options.levels - level);
    if (level == options.levels || n <= 1) {
      progress += n * remaining;
      return;
    }
    bow_internal::ClusterOptions cluster_options;
    cluster_options.k = options.branching;
    cluster_options.max_iterations = options.max_iterations;
    cluster_options.seed = seed;
    cluster_options.parallel_min = options.parallel_assign_min;
    const std::span<const Descriptor> slice(points.data() + begin, n);
    bow_internal::ClusterResult clusters = bow_internal::ClusterDescriptors(slice, cluster_options);
    if (n > static_cast<std::size_t>(options.branching)) {
      ++clustered_nodes;
      iterations += static_cast<std::size_t>(clusters.iterations);
      if (!clusters.converged) ++unconverged_nodes;
    }
    if (clusters.centres.size() <= 1) {  // identical points: nothing to split
      progress += n * remaining;
      return;
    }

    // Stable counting sort of the slice by cluster, so each child owns a contiguous range.
    const std::size_t c = clusters.centres.size();
    std::vector<std::size_t> offset(c + 1, 0);
    for (std::uint32_t l : clusters.labels) ++offset[l + 1];
    for (std::size_t j = 0; j < c; ++j) offset[j + 1] += offset[j];
    {
      std::vector<Descriptor> sorted(n);
      std::vector<std::size_t> cursor(offset.begin(), offset.end() - 1);
      for (std::size_t i = 0; i < n; ++i) sorted[cursor[clusters.labels[i]]++] = slice[i];
      std::copy(sorted.begin(), sorted.end(), points.begin() + static_cast<std::ptrdiff_t>(begin));
    }
    clusters.labels = {};
    node.children.resize(c);
    for (std::size_t j = 0; j < c; ++j) node.children[j].centre = clusters.centres[j];
    progress += n;

    tbb::parallel_for(std::size_t{0}, c, [&](std::size_t j) {
      Build(node.children[j], begin + offset[j], begin + offset[j + 1], level + 1,
            bow_internal::ChildSeed(seed, j));
    });
  }
};

// DBoW2's node numbering: a node's children get consecutive ids when it is expanded, then
// each child is expanded in turn (depth first).
void EmitChildren(const TrainNode& node, NodeId id, std::vector<VocabularyNode>* nodes) {
  const auto first = static_cast<NodeId>(nodes->size());
  for (const TrainNode& child : node.children) {
    VocabularyNode out;
    out.parent = id;
    out.is_leaf = child.children.empty();
    out.descriptor = child.centre;
    nodes->push_back(out);
  }
  for (std::size_t j = 0; j < node.children.size(); ++j) {
    EmitChildren(node.children[j], first + static_cast<NodeId>(j), nodes);
  }
}

// Runs `work` on a helper thread while this thread redraws `label`'s progress bar from the
// atomic counter the work advances (Progress itself is single-threaded).
void RunWithProgress(const char* label, std::size_t total, bool quiet,
                     const std::atomic<std::size_t>& counter, const std::function<void()>& work) {
  std::mutex mutex;
  std::condition_variable cv;
  bool finished = false;
  std::exception_ptr error;
  std::thread worker([&] {
    try {
      work();
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard lock(mutex);
    finished = true;
    cv.notify_one();
  });
  Progress progress(label, total, quiet);
  {
    std::unique_lock lock(mutex);
    while (!finished) {
      cv.wait_for(lock, std::chrono::milliseconds(200), [&] { return finished; });
      const std::size_t done = std::min(counter.load(), total);
      if (done > progress.done()) progress.Add(done - progress.done());
    }
  }
  worker.join();
  progress.Finish();
  if (error) std::rethrow_exception(error);
}

}  // namespace

Vocabulary Vocabulary::Train(const std::vector<std::vector<Descriptor>>& images,
                             const VocabularyTrainOptions& options) {
  options.Check();
  std::vector<Descriptor> points;
  std::size_t total = 0;
  for (const auto& image : images) total += image.size();
  if (total == 0) throw Error("vocabulary training: no descriptors in the training images");
  points.reserve(total);
  for (const auto& image : images) points.insert(points.end(), image.begin(), image.end());
  PKSLAM_LOG_INFO("vocabulary: training k={} L={} on {} descriptors from {} images",
                  options.branching, options.levels, total, images.size());

  const Descriptor first_point = points.front();

  // 1. Hierarchical k-means.
  TrainNode root;
  std::atomic<std::size_t> progress{0};
  std::atomic<std::size_t> clustered{0};
  std::atomic<std::size_t> unconverged{0};
  std::atomic<std::size_t> iterations{0};
  const TreeBuilder builder{options, points, progress, clustered, unconverged, iterations};
  RunWithProgress("vocab k-means", total * static_cast<std::size_t>(options.levels), options.quiet,
                  progress, [&] { builder.Build(root, 0, points.size(), 0, options.seed); });
  points = {};
  PKSLAM_LOG_INFO(
      "vocabulary: k-means on {} nodes, {:.1f} Lloyd iterations per node on average, {} stopped "
      "at max_iterations {}",
      clustered.load(), clustered > 0 ? static_cast<double>(iterations) / clustered : 0.0,
      unconverged.load(), options.max_iterations);

  std::vector<VocabularyNode> nodes(1);
  EmitChildren(root, 0, &nodes);
  root = {};
  if (nodes.size() == 1) {  // a single distinct descriptor: one word under the root
    VocabularyNode only;
    only.is_leaf = true;
    only.descriptor = first_point;
    nodes.push_back(only);
  }
  VocabularyParams params;
  params.branching = options.branching;
  params.levels = options.levels;
  params.scoring = Scoring::kL1;
  params.weighting = options.weighting;
  Vocabulary vocabulary = FromNodes(params, std::move(nodes));

  // 2. Word weights. TF / binary: 1. IDF / TF-IDF: log(N / n_i), n_i = number of training
  // images with word i. A word no training image quantises to (possible: greedy descent may
  // leave a point's cluster) counts as seen once, i.e. as the rarest word, not as noise.
  if (options.weighting == Weighting::kTf || options.weighting == Weighting::kBinary) {
    for (NodeId node : vocabulary.word_nodes_) vocabulary.weights_[node] = 1.0;
    return vocabulary;
  }
  std::vector<std::vector<WordId>> image_words(images.size());
  std::atomic<std::size_t> images_done{0};
  RunWithProgress("vocab idf", images.size(), options.quiet, images_done, [&] {
    tbb::parallel_for(std::size_t{0}, images.size(), [&](std::size_t i) {
      std::vector<WordId>& words = image_words[i];
      words.reserve(images[i].size());
      for (const Descriptor& d : images[i]) words.push_back(vocabulary.FindWord(d));
      std::sort(words.begin(), words.end());
      words.erase(std::unique(words.begin(), words.end()), words.end());
      ++images_done;
    });
  });
  std::vector<std::uint32_t> document_frequency(vocabulary.word_count(), 0);
  for (const auto& words : image_words) {
    for (WordId w : words) ++document_frequency[w];
  }
  const auto n_images = static_cast<double>(images.size());
  for (WordId w = 0; w < vocabulary.word_count(); ++w) {
    const double n_i = std::max<double>(1.0, document_frequency[w]);
    vocabulary.weights_[vocabulary.word_nodes_[w]] = std::log(n_images / n_i);
  }
  return vocabulary;
}

}  // namespace pkslam
