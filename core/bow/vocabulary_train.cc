// Vocabulary training: hierarchical k-means++ (DBoW2's HKmeans) over all training descriptors,
// then word weights from the training images' document frequencies.
//
// Threads: the tree grows level by level. Nodes of one level are independent: the large ones
// are clustered one after the other with their assignment steps split across the threads, the
// others concurrently, one node per task. A task owns its node and a disjoint slice of the
// shared descriptor array; the only shared mutable state is the atomic progress counter, read
// by the calling thread to draw the progress bar. Every node's seed derives from its path in
// the tree and the results are collected in frontier order, so the vocabulary does not depend
// on the thread count or on scheduling.
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
#include "core/bow/parallel.h"
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

// A node still to be split: its points are points[begin, end).
struct PendingNode {
  TrainNode* node = nullptr;
  std::size_t begin = 0;
  std::size_t end = 0;
  std::uint64_t seed = 0;
};

struct SplitStats {
  std::atomic<std::size_t> clustered{0};    // nodes split by k-means proper
  std::atomic<std::size_t> unconverged{0};  // of which stopped by max_iterations
  std::atomic<std::size_t> iterations{0};   // Lloyd iterations over all of them
};

class TreeBuilder {
 public:
  TreeBuilder(const VocabularyTrainOptions& options, int threads, std::vector<Descriptor>& points,
              std::atomic<std::size_t>& progress)
      : options_(options), threads_(threads), points_(points), progress_(progress) {}

  const SplitStats& stats() const { return stats_; }

  void Build(TrainNode& root, std::uint64_t seed) {
    std::vector<PendingNode> frontier = {{&root, 0, points_.size(), seed}};
    for (int level = 0; !frontier.empty(); ++level) {
      std::vector<std::vector<PendingNode>> children(frontier.size());
      std::vector<std::size_t> small;
      for (std::size_t i = 0; i < frontier.size(); ++i) {
        const std::size_t n = frontier[i].end - frontier[i].begin;
        if (threads_ > 1 && n >= options_.parallel_assign_min) {
          children[i] = Split(frontier[i], level, threads_);
        } else {
          small.push_back(i);
        }
      }
      bow_internal::ParallelFor(small.size(), threads_, [&](std::size_t j) {
        children[small[j]] = Split(frontier[small[j]], level, 1);
      });
      frontier.clear();
      for (auto& c : children) frontier.insert(frontier.end(), c.begin(), c.end());
    }
  }

 private:
  // Clusters one node (at `level`) into children; returns those that need splitting further.
  std::vector<PendingNode> Split(const PendingNode& pending, int level, int threads) {
    const std::size_t n = pending.end - pending.begin;
    const auto remaining = static_cast<std::size_t>(options_.levels - level);
    if (level == options_.levels || n <= 1) {
      progress_ += n * remaining;
      return {};
    }
    bow_internal::ClusterOptions cluster_options;
    cluster_options.k = options_.branching;
    cluster_options.max_iterations = options_.max_iterations;
    cluster_options.seed = pending.seed;
    cluster_options.parallel_min = options_.parallel_assign_min;
    cluster_options.threads = threads;
    const std::span<const Descriptor> slice(points_.data() + pending.begin, n);
    bow_internal::ClusterResult clusters = bow_internal::ClusterDescriptors(slice, cluster_options);
    if (n > static_cast<std::size_t>(options_.branching)) {
      ++stats_.clustered;
      stats_.iterations += static_cast<std::size_t>(clusters.iterations);
      if (!clusters.converged) ++stats_.unconverged;
      if (n >= 100000) {
        PKSLAM_LOG_DEBUG("vocabulary: level {} node of {} points: {} clusters, {} iterations{}",
                         level, n, clusters.centres.size(), clusters.iterations,
                         clusters.converged ? "" : " (not converged)");
      }
    }
    if (clusters.centres.size() <= 1) {  // identical points: nothing to split
      progress_ += n * remaining;
      return {};
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
      std::copy(sorted.begin(), sorted.end(),
                points_.begin() + static_cast<std::ptrdiff_t>(pending.begin));
    }
    TrainNode& node = *pending.node;
    node.children.resize(c);
    std::vector<PendingNode> next;
    next.reserve(c);
    for (std::size_t j = 0; j < c; ++j) {
      node.children[j].centre = clusters.centres[j];
      next.push_back(PendingNode{&node.children[j], pending.begin + offset[j],
                                 pending.begin + offset[j + 1],
                                 bow_internal::ChildSeed(pending.seed, j)});
    }
    progress_ += n;
    return next;
  }

  const VocabularyTrainOptions& options_;
  const int threads_;
  std::vector<Descriptor>& points_;  // reordered in place: each node's points contiguous
  std::atomic<std::size_t>& progress_;
  SplitStats stats_;
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
  const int threads = bow_internal::ResolveThreadCount(options.threads);
  TrainNode root;
  std::atomic<std::size_t> progress{0};
  TreeBuilder builder(options, threads, points, progress);
  RunWithProgress("vocab k-means", total * static_cast<std::size_t>(options.levels), options.quiet,
                  progress, [&] { builder.Build(root, options.seed); });
  points = {};
  const SplitStats& stats = builder.stats();
  PKSLAM_LOG_INFO(
      "vocabulary: k-means on {} nodes ({} threads), {:.1f} Lloyd iterations per node on "
      "average, {} stopped at max_iterations {}",
      stats.clustered.load(), threads,
      stats.clustered > 0 ? static_cast<double>(stats.iterations) / stats.clustered : 0.0,
      stats.unconverged.load(), options.max_iterations);

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
    bow_internal::ParallelFor(images.size(), threads, [&](std::size_t i) {
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
