// "Did you mean ...?" for a mistyped flag, value or settings key: the candidate nearest to a word
// by edit distance, when it is near enough to be a typo rather than another word.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pkslam {

// Edit distance: insertions, deletions, substitutions and swaps of neighbours, one each (optimal
// string alignment); ASCII case-insensitive, since a user typing --Sensor means --sensor.
std::size_t EditDistance(std::string_view a, std::string_view b);

// The candidate with the smallest edit distance to `word`, if that distance is at most
// max(1, word.size() / 3) (two typos in a six-letter word, one in a three-letter one), or if the
// word is a prefix of exactly one candidate. Ties go to the first candidate listed.
std::optional<std::string> ClosestMatch(std::string_view word,
                                        const std::vector<std::string>& candidates);

// " (did you mean 'X'?)" for the closest match, or "" when there is none.
std::string DidYouMean(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace pkslam
