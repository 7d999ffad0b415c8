#include "map_model/keyframe_database.h"

#include <algorithm>
#include <limits>

#include "core/bow/vocabulary.h"
#include "core/util/error.h"
#include "map_model/frame.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"

namespace pkslam {
namespace {

// Higher group score first; ties by keyframe id so the order never depends on pointers.
bool BetterGroup(const PlaceCandidate& a, const PlaceCandidate& b) {
  if (a.group_score != b.group_score) return a.group_score > b.group_score;
  return a.keyframe->id() < b.keyframe->id();
}

}  // namespace

void KeyFrameDatabaseOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_common_words_ratio >= 0 && min_common_words_ratio <= 1,
                      "min_common_words_ratio", "{}", min_common_words_ratio);
  PKSLAM_CHECK_OPTION(group_size >= 0, "group_size", "{}", group_size);
  PKSLAM_CHECK_OPTION(min_group_score_ratio >= 0 && min_group_score_ratio <= 1,
                      "min_group_score_ratio", "{}", min_group_score_ratio);
}

KeyFrameDatabase::KeyFrameDatabase(const Vocabulary& vocabulary, KeyFrameDatabaseOptions options)
    : vocabulary_(vocabulary), options_(options), inverted_(vocabulary.word_count()) {
  options_.Check();
}

void KeyFrameDatabase::Add(const MapWriteLock& lock, KeyFrame* keyframe) {
  RequireWriteLock(lock, "KeyFrameDatabase::Add");
  PKSLAM_CHECK(keyframe != nullptr, "null keyframe");
  for (const BowEntry& entry : keyframe->bow()) {
    PKSLAM_CHECK(entry.word_id < inverted_.size(), "keyframe {} has word {} >= word count {}",
                 keyframe->id(), entry.word_id, inverted_.size());
  }
  Unindex(keyframe);
  std::vector<WordId> words;
  words.reserve(keyframe->bow().size());
  for (const BowEntry& entry : keyframe->bow()) {
    inverted_[entry.word_id].push_back(keyframe);
    words.push_back(entry.word_id);
  }
  words_of_[keyframe->id()] = {keyframe, std::move(words)};
}

void KeyFrameDatabase::Erase(const MapWriteLock& lock, const KeyFrame* keyframe) {
  RequireWriteLock(lock, "KeyFrameDatabase::Erase");
  Unindex(keyframe);
}

void KeyFrameDatabase::Unindex(const KeyFrame* keyframe) {
  auto it = words_of_.find(keyframe->id());
  if (it == words_of_.end() || it->second.first != keyframe) return;
  for (const WordId word : it->second.second) {
    auto& list = inverted_[word];
    list.erase(std::remove(list.begin(), list.end(), keyframe), list.end());
  }
  words_of_.erase(it);
}

void KeyFrameDatabase::Clear(const Map* map) {
  std::vector<const KeyFrame*> doomed;
  for (const auto& [id, entry] : words_of_) {
    if (entry.first->map() == map) doomed.push_back(entry.first);
  }
  for (const KeyFrame* kf : doomed) Unindex(kf);
}

void KeyFrameDatabase::Clear() {
  for (auto& list : inverted_) list.clear();
  words_of_.clear();
}

bool KeyFrameDatabase::Contains(const KeyFrame* keyframe) const {
  auto it = words_of_.find(keyframe->id());
  return it != words_of_.end() && it->second.first == keyframe;
}

template <typename Accept>
std::map<KeyFrameId, std::pair<KeyFrame*, int>> KeyFrameDatabase::CountCommonWords(
    const BowVector& bow, Accept accept) const {
  std::map<KeyFrameId, std::pair<KeyFrame*, int>> counts;
  for (const BowEntry& entry : bow) {
    if (entry.word_id >= inverted_.size()) continue;
    for (KeyFrame* kf : inverted_[entry.word_id]) {
      if (kf->IsBad() || !accept(kf)) continue;
      auto& slot = counts[kf->id()];
      slot.first = kf;
      ++slot.second;
    }
  }
  return counts;
}

std::vector<PlaceCandidate> KeyFrameDatabase::ScoreGroups(
    const BowVector& bow, const std::map<KeyFrameId, std::pair<KeyFrame*, int>>& counts,
    double min_common_words_ratio) const {
  int max_common = 0;
  for (const auto& [id, entry] : counts) max_common = std::max(max_common, entry.second);
  const double min_common = min_common_words_ratio * max_common;

  // Only keyframes above the common-words threshold get a score; the others count as 0 when
  // they appear in a group (ORB-SLAM would read a stale score left by an earlier query).
  std::map<KeyFrameId, Scored> scored;
  for (const auto& [id, entry] : counts) {
    if (entry.second > min_common) {
      scored[id] = {entry.first, vocabulary_.Score(bow, entry.first->bow())};
    }
  }

  std::vector<PlaceCandidate> groups;
  groups.reserve(scored.size());
  for (const auto& [id, s] : scored) {
    PlaceCandidate group{s.keyframe, s.score, s.score};
    for (KeyFrame* neighbour : s.keyframe->BestCovisibles(options_.group_size)) {
      auto it = scored.find(neighbour->id());
      if (it == scored.end()) continue;
      group.group_score += it->second.score;
      if (it->second.score > group.score) {
        group.keyframe = it->second.keyframe;
        group.score = it->second.score;
      }
    }
    groups.push_back(group);
  }
  return groups;
}

std::vector<PlaceCandidate> KeyFrameDatabase::DetectRelocalisationCandidates(const Frame& frame,
                                                                             const Map* map) const {
  return DetectRelocalisationCandidates(frame, map, options_,
                                        std::numeric_limits<std::size_t>::max());
}

std::vector<PlaceCandidate> KeyFrameDatabase::DetectRelocalisationCandidates(
    const Frame& frame, const Map* map, const KeyFrameDatabaseOptions& ratios,
    std::size_t max_candidates) const {
  PKSLAM_CHECK(frame.HasBoW(), "frame {} has no BoW vector", frame.id());
  const auto counts = CountCommonWords(
      frame.bow(), [map](const KeyFrame* kf) { return map == nullptr || kf->map() == map; });
  std::vector<PlaceCandidate> groups =
      ScoreGroups(frame.bow(), counts, ratios.min_common_words_ratio);
  if (groups.empty()) return {};

  std::sort(groups.begin(), groups.end(), BetterGroup);
  const double min_score = ratios.min_group_score_ratio * groups.front().group_score;
  std::vector<PlaceCandidate> out;
  std::map<KeyFrameId, bool> added;
  for (const PlaceCandidate& g : groups) {
    if (g.group_score <= min_score || out.size() >= max_candidates) break;
    if (!added.emplace(g.keyframe->id(), true).second) continue;
    out.push_back(g);
  }
  return out;
}

LoopAndMergeCandidates KeyFrameDatabase::DetectLoopAndMergeCandidates(const KeyFrame* keyframe,
                                                                      int n) const {
  PKSLAM_CHECK(n >= 0, "n = {}", n);
  std::map<KeyFrameId, bool> excluded;
  excluded[keyframe->id()] = true;
  for (const KeyFrame* kf : keyframe->ConnectedKeyFrames()) excluded[kf->id()] = true;
  const auto counts = CountCommonWords(keyframe->bow(), [&excluded](const KeyFrame* kf) {
    return kf->map() != nullptr && excluded.count(kf->id()) == 0;
  });
  std::vector<PlaceCandidate> groups =
      ScoreGroups(keyframe->bow(), counts, options_.min_common_words_ratio);
  std::sort(groups.begin(), groups.end(), BetterGroup);

  LoopAndMergeCandidates out;
  const auto limit = static_cast<std::size_t>(n);
  std::map<KeyFrameId, bool> added;
  for (const PlaceCandidate& g : groups) {
    if (out.loop.size() >= limit && out.merge.size() >= limit) break;
    if (g.keyframe->IsBad() || !added.emplace(g.keyframe->id(), true).second) continue;
    auto& list = g.keyframe->map() == keyframe->map() ? out.loop : out.merge;
    if (list.size() < limit) list.push_back(g);
  }
  return out;
}

}  // namespace pkslam
