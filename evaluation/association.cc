#include "evaluation/association.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "core/util/error.h"

namespace pkslam {
namespace {

std::int64_t SecondsToNs(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

bool NonDecreasing(std::span<const std::int64_t> t) {
  return std::adjacent_find(t.begin(), t.end(), std::greater<>()) == t.end();
}

// The double nearest to t_ns * 1e-9, i.e. what numpy parses from the decimal text of the same
// stamp (whole seconds are exact in a double; the fraction adds one correctly rounded step).
double DoubleSeconds(std::int64_t t_ns) {
  std::int64_t seconds = t_ns / 1000000000;
  std::int64_t fraction = t_ns % 1000000000;
  if (fraction < 0) {
    fraction += 1000000000;
    --seconds;
  }
  return static_cast<double>(seconds) + static_cast<double>(fraction) / 1e9;
}

}  // namespace

void AssociationOptions::Check() const {
  PKSLAM_CHECK_OPTION(std::isfinite(max_diff_s) && max_diff_s >= 0.0 && max_diff_s < 1e9,
                      "max_diff_s", "{}", max_diff_s);
  PKSLAM_CHECK_OPTION(std::isfinite(offset_s) && std::abs(offset_s) < 1e9, "offset_s", "{}",
                      offset_s);
}

std::vector<IndexPair> AssociateTimestamps(std::span<const std::int64_t> ref_t_ns,
                                           std::span<const std::int64_t> est_t_ns,
                                           const AssociationOptions& options) {
  options.Check();
  PKSLAM_CHECK(NonDecreasing(ref_t_ns) && NonDecreasing(est_t_ns),
               "association needs timestamps sorted by time");

  // evo: the shorter trajectory drives; the estimate drives when both are equally long.
  const bool est_drives = est_t_ns.size() <= ref_t_ns.size();
  const std::span<const std::int64_t> driver = est_drives ? est_t_ns : ref_t_ns;
  const std::span<const std::int64_t> other = est_drives ? ref_t_ns : est_t_ns;
  // evo adds the offset to the other trajectory's stamps, negated when those are the
  // reference's (so that it always shifts the estimate's clock).
  const double other_shift_s = est_drives ? -options.offset_s : options.offset_s;
  const std::int64_t other_shift_ns =
      est_drives ? -SecondsToNs(options.offset_s) : SecondsToNs(options.offset_s);
  std::vector<double> other_s(other.size());
  for (std::size_t j = 0; j < other.size(); ++j) {
    other_s[j] = DoubleSeconds(other[j]) + other_shift_s;
  }

  struct Match {
    std::size_t driver;
    std::size_t other;
    double diff_s;
  };
  std::vector<Match> matches;
  matches.reserve(driver.size());
  for (std::size_t i = 0; i < driver.size(); ++i) {
    // Exact integer search for the neighbourhood, then evo's double-precision comparison
    // among the nearest candidates (it decides exact ties and differences of exactly
    // max_diff the way evo does): the smallest difference, the earliest index on a tie.
    const std::int64_t t_other_clock = driver[i] - other_shift_ns;
    const std::size_t upper = static_cast<std::size_t>(
        std::lower_bound(other.begin(), other.end(), t_other_clock) - other.begin());
    const double t_s = DoubleSeconds(driver[i]);
    const std::size_t begin = upper >= 2 ? upper - 2 : 0;
    const std::size_t end = std::min(other.size(), upper + 2);
    std::size_t best = other.size();
    double best_diff = 0.0;
    for (std::size_t j = begin; j < end; ++j) {
      const double diff = std::abs(other_s[j] - t_s);
      if (best == other.size() || diff < best_diff) {
        best = j;
        best_diff = diff;
      }
    }
    if (best < other.size() && best_diff <= options.max_diff_s) {
      matches.push_back({i, best, best_diff});
    }
  }

  if (options.one_to_one) {
    // Matches of one `other` pose are adjacent (nearest-neighbour matching of sorted stamps is
    // monotone); keep the closest of each run, the earliest on a tie. Repeats of one stamp in
    // the driving trajectory all stay, as in evo (they are the same instant, not a second
    // pose competing for the pair).
    std::vector<Match> unique;
    unique.reserve(matches.size());
    for (const Match& m : matches) {
      const bool repeat = !unique.empty() && driver[unique.back().driver] == driver[m.driver];
      if (!unique.empty() && unique.back().other == m.other && !repeat) {
        if (m.diff_s < unique.back().diff_s) unique.back() = m;
      } else {
        unique.push_back(m);
      }
    }
    matches.swap(unique);
  }

  std::vector<IndexPair> pairs;
  pairs.reserve(matches.size());
  for (const Match& m : matches) {
    pairs.push_back(est_drives ? IndexPair{m.other, m.driver} : IndexPair{m.driver, m.other});
  }
  return pairs;
}

}  // namespace pkslam
