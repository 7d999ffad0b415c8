#include "core/features/quadtree_distribution.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace pkslam {
namespace {

// A node covers [x0, x1) x [y0, y1) and owns order[begin, end).
struct Node {
  int x0, y0, x1, y1;
  int begin, end;

  int Count() const { return end - begin; }
  bool Splittable() const { return Count() > 1 && (x1 - x0 > 1 || y1 - y0 > 1); }
};

class Quadtree {
 public:
  Quadtree(std::span<const cv::KeyPoint> candidates, cv::Size area)
      : kps_(candidates), order_(candidates.size()), scratch_(candidates.size()) {
    // Roughly square initial nodes side by side along x, as ORB-SLAM (which assumes a
    // landscape image; a portrait one gets a single initial node).
    const int n_initial =
        std::max(1, static_cast<int>(std::lround(double(area.width) / area.height)));
    std::iota(order_.begin(), order_.end(), 0);
    std::vector<int> column(kps_.size());
    for (std::size_t i = 0; i < kps_.size(); ++i) {
      column[i] =
          std::clamp(static_cast<int>(kps_[i].pt.x * n_initial / area.width), 0, n_initial - 1);
    }
    std::stable_sort(order_.begin(), order_.end(),
                     [&](int a, int b) { return column[a] < column[b]; });
    int begin = 0;
    for (int c = 0; c < n_initial; ++c) {
      int end = begin;
      while (end < static_cast<int>(order_.size()) && column[order_[end]] == c) ++end;
      const int x0 = static_cast<int>(std::lround(double(c) * area.width / n_initial));
      const int x1 = static_cast<int>(std::lround(double(c + 1) * area.width / n_initial));
      if (end > begin) nodes_.push_back({x0, 0, x1, area.height, begin, end});
      begin = end;
    }
  }

  void Refine(int target) {
    std::vector<int> expandable;
    while (static_cast<int>(nodes_.size()) < target) {
      expandable.clear();
      for (int i = 0; i < static_cast<int>(nodes_.size()); ++i) {
        if (nodes_[i].Splittable()) expandable.push_back(i);
      }
      if (expandable.empty()) return;
      const bool split_all =
          nodes_.size() + 3 * expandable.size() <= static_cast<std::size_t>(target);
      if (!split_all) {
        // Split the most populated nodes first (ties: earlier node first).
        std::stable_sort(expandable.begin(), expandable.end(),
                         [&](int a, int b) { return nodes_[a].Count() > nodes_[b].Count(); });
      }
      std::vector<bool> split(nodes_.size(), false);
      std::vector<Node> children;
      int n_after = static_cast<int>(nodes_.size());
      for (int i : expandable) {
        const int before = static_cast<int>(children.size());
        Split(nodes_[i], &children);
        split[i] = true;
        n_after += static_cast<int>(children.size()) - before - 1;
        if (!split_all && n_after >= target) break;
      }
      std::vector<Node> next;
      next.reserve(n_after);
      for (std::size_t i = 0; i < nodes_.size(); ++i) {
        if (!split[i]) next.push_back(nodes_[i]);
      }
      next.insert(next.end(), children.begin(), children.end());
      nodes_.swap(next);
    }
  }

  // Strongest keypoint of every node, trimmed to `target` by response, ascending indices.
  std::vector<int> Select(int target) const {
    std::vector<int> best;
    best.reserve(nodes_.size());
    for (const Node& node : nodes_) {
      int pick = order_[node.begin];
      for (int k = node.begin + 1; k < node.end; ++k) {
        if (Stronger(order_[k], pick)) pick = order_[k];
      }
      best.push_back(pick);
    }
    if (static_cast<int>(best.size()) > target) {
      std::nth_element(best.begin(), best.begin() + target, best.end(),
                       [&](int a, int b) { return Stronger(a, b); });
      best.resize(target);
    }
    std::sort(best.begin(), best.end());
    return best;
  }

 private:
  bool Stronger(int a, int b) const {
    const float ra = kps_[a].response;
    const float rb = kps_[b].response;
    return ra > rb || (ra == rb && a < b);
  }

  // Appends the non-empty quadrants of `node`, keeping the candidate order inside each.
  void Split(const Node& node, std::vector<Node>* out) {
    const int mx = node.x0 + (node.x1 - node.x0 + 1) / 2;
    const int my = node.y0 + (node.y1 - node.y0 + 1) / 2;
    std::array<int, 4> count{};
    for (int k = node.begin; k < node.end; ++k) ++count[Quadrant(order_[k], mx, my)];
    std::array<int, 4> start{};
    start[0] = node.begin;
    for (int q = 1; q < 4; ++q) start[q] = start[q - 1] + count[q - 1];
    std::array<int, 4> fill = start;
    for (int k = node.begin; k < node.end; ++k) {
      scratch_[fill[Quadrant(order_[k], mx, my)]++] = order_[k];
    }
    std::copy(scratch_.begin() + node.begin, scratch_.begin() + node.end,
              order_.begin() + node.begin);
    const std::array<int, 4> qx0 = {node.x0, mx, node.x0, mx};
    const std::array<int, 4> qx1 = {mx, node.x1, mx, node.x1};
    const std::array<int, 4> qy0 = {node.y0, node.y0, my, my};
    const std::array<int, 4> qy1 = {my, my, node.y1, node.y1};
    for (int q = 0; q < 4; ++q) {
      if (count[q] > 0) out->push_back({qx0[q], qy0[q], qx1[q], qy1[q], start[q], fill[q]});
    }
  }

  int Quadrant(int i, int mx, int my) const {
    return (kps_[i].pt.x >= mx ? 1 : 0) + (kps_[i].pt.y >= my ? 2 : 0);
  }

  std::span<const cv::KeyPoint> kps_;
  std::vector<int> order_;
  std::vector<int> scratch_;
  std::vector<Node> nodes_;
};

}  // namespace

std::vector<int> DistributeQuadtree(std::span<const cv::KeyPoint> candidates, cv::Size area,
                                    int target) {
  if (target <= 0 || candidates.empty() || area.width <= 0 || area.height <= 0) return {};
  Quadtree tree(candidates, area);
  tree.Refine(target);
  return tree.Select(target);
}

}  // namespace pkslam
