// Keyframe database: an inverted index from vocabulary words to the keyframes whose BoW vector
// contains them, and the place-recognition queries of ORB-SLAM3 built on it (relocalisation
// candidates for a frame, loop and merge candidates for a keyframe).
//
// Threading (docs/architecture.md): the database is part of the map model and is guarded by
// the Atlas mutex. Add and Erase take the write lock and throw without it; Clear is called by a
// map being cleared or destroyed, under its caller's exclusive lock; the queries need the shared
// lock (they also read keyframes' BoW vectors, covisibility and maps). Queries keep all their
// scratch state in locals, so several readers may query at once.
//
// Ownership: entries are non-owning KeyFrame pointers. A keyframe must be erased before it is
// destroyed; retired keyframes stay alive in their map, so erasing on retirement (SetBad) and
// clearing a map's entries before the map is cleared or destroyed keeps every entry valid.
//
// Determinism: candidates and their scores are accumulated in id-ordered containers and ties
// are broken by keyframe id, never by pointer value.
#pragma once

#include <cstddef>
#include <map>
#include <vector>

#include "core/bow/bow_vector.h"
#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;
class Vocabulary;

struct KeyFrameDatabaseOptions {
  // Candidates must share more than this fraction of the maximum number of common words
  // found among all keyframes sharing a word with the query (ORB-SLAM: 0.8).
  double min_common_words_ratio = 0.8;
  // Covisibles of each candidate whose scores are accumulated into its group (ORB-SLAM: 10).
  int group_size = 10;
  // Relocalisation keeps groups whose accumulated score exceeds this fraction of the best
  // group's (ORB-SLAM: 0.75).
  double min_group_score_ratio = 0.75;

  void Check() const;
};

// One candidate of a query, with the scores that selected it (for logs and statistics).
struct PlaceCandidate {
  KeyFrame* keyframe = nullptr;  // best-scoring keyframe of its covisibility group
  double score = 0;              // its own BoW similarity to the query
  double group_score = 0;        // accumulated similarity of the group
};

struct LoopAndMergeCandidates {
  std::vector<PlaceCandidate> loop;   // in the query keyframe's map, best group first
  std::vector<PlaceCandidate> merge;  // in other maps, best group first
};

class KeyFrameDatabase {
 public:
  // `vocabulary` must outlive the database; word ids of added keyframes must be below its
  // word count.
  explicit KeyFrameDatabase(const Vocabulary& vocabulary, KeyFrameDatabaseOptions options = {});
  KeyFrameDatabase(const KeyFrameDatabase&) = delete;
  KeyFrameDatabase& operator=(const KeyFrameDatabase&) = delete;

  // Indexes the keyframe under every word of its BoW vector (which must already be computed).
  // Adding a keyframe twice re-indexes it.
  void Add(const MapWriteLock& lock, KeyFrame* keyframe);
  // Removes the keyframe from the index (works after its features were released, because the
  // database remembers the words it indexed). No-op for unknown keyframes.
  void Erase(const MapWriteLock& lock, const KeyFrame* keyframe);
  // Removes every keyframe currently belonging to `map` (call before the map is cleared or
  // destroyed: the map's keyframes are recognised by KeyFrame::map()). Exclusive lock.
  void Clear(const Map* map);
  // Removes everything. Exclusive lock.
  void Clear();

  std::size_t size() const { return words_of_.size(); }
  bool Contains(const KeyFrame* keyframe) const;

  // ORB-SLAM3's DetectRelocalizationCandidates: live keyframes of `map` (any map when null)
  // sharing words with the frame; those with more than min_common_words_ratio * max common
  // words are scored (L1), each scored keyframe's group (itself + its group_size best
  // covisibles that were scored) accumulates the scores, and the best keyframe of every group
  // scoring more than min_group_score_ratio * best group is returned, best group first.
  // Requires the frame's BoW. Shared lock.
  std::vector<PlaceCandidate> DetectRelocalisationCandidates(const Frame& frame,
                                                             const Map* map) const;
  // The same with `ratios`' two thresholds in place of the database's, at most max_candidates
  // returned: the wider search after repeated failure (lower ratios keep keyframes that share
  // fewer words, as a view seen from further off does).
  std::vector<PlaceCandidate> DetectRelocalisationCandidates(const Frame& frame, const Map* map,
                                                             const KeyFrameDatabaseOptions& ratios,
                                                             std::size_t max_candidates) const;

  // ORB-SLAM3's DetectNBestCandidates: like the relocalisation query but excluding the query
  // keyframe and its covisibility neighbours; groups are ranked by accumulated score and the
  // best keyframes are split into up to n loop candidates (same map as the query) and up to n
  // merge candidates (other maps). Shared lock.
  LoopAndMergeCandidates DetectLoopAndMergeCandidates(const KeyFrame* keyframe, int n = 3) const;

 private:
  // Erase's work (Clear's too).
  void Unindex(const KeyFrame* keyframe);
  struct Scored {
    KeyFrame* keyframe;
    double score;
  };
  // Counts common words per keyframe (id-ordered) for a query BoW vector, skipping keyframes
  // that `accept` rejects.
  template <typename Accept>
  std::map<KeyFrameId, std::pair<KeyFrame*, int>> CountCommonWords(const BowVector& bow,
                                                                   Accept accept) const;
  // Scores the keyframes sharing more than min_common_words_ratio * the most common words and
  // accumulates group scores; returns one PlaceCandidate per scored keyframe (in id order of the
  // scored keyframe).
  std::vector<PlaceCandidate> ScoreGroups(
      const BowVector& bow, const std::map<KeyFrameId, std::pair<KeyFrame*, int>>& counts,
      double min_common_words_ratio) const;

  const Vocabulary& vocabulary_;
  KeyFrameDatabaseOptions options_;
  // word -> keyframes indexed under it (unordered; queries order by id).
  std::vector<std::vector<KeyFrame*>> inverted_;
  // keyframe id -> (keyframe, the words it was indexed under).
  std::map<KeyFrameId, std::pair<KeyFrame*, std::vector<WordId>>> words_of_;
};

}  // namespace pkslam
