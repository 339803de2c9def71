// A tournament (winner) tree over the neighbour pairs: each leaf holds a key (a lower bound
// of the pair's next impact time [s], +inf for none) and each inner node the smallest key
// of its subtree with its leaf. An impact changes three adjacent leaves, whose paths to the
// root merge after a level or two, so one O(log N) walk updates all three; a binary heap
// needs three independent sifts. Internal to the engine; not installed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace collision_lab {
namespace core {
namespace nbody_detail {

class TournamentTree {
 public:
  explicit TournamentTree(std::size_t leaves) {
    base_ = 1;
    while (base_ < leaves) base_ *= 2;
    nodes_.assign(2 * base_, Node{kNone, 0});
    for (std::size_t i = 0; i < base_; ++i) nodes_[base_ + i].leaf = static_cast<std::uint32_t>(i);
    rebuild();
  }

  double key(std::size_t leaf) const { return nodes_[base_ + leaf].key; }
  /// Sets a leaf without propagating; call update() or rebuild() afterwards.
  void set(std::size_t leaf, double key) { nodes_[base_ + leaf].key = key; }

  /// Propagates the leaves first..last (inclusive) to the root.
  void update(std::size_t first, std::size_t last) {
    std::size_t lo = (base_ + first) >> 1, hi = (base_ + last) >> 1;
    for (; lo >= 1; lo >>= 1, hi >>= 1) {
      bool changed = false;
      for (std::size_t n = lo; n <= hi; ++n) changed |= refresh(n);
      if (lo == hi && !changed) return;  // the ancestors see the same subtree minimum
    }
  }

  void rebuild() {
    for (std::size_t n = base_ - 1; n >= 1; --n) refresh(n);
  }

  std::size_t minLeaf() const { return nodes_[1].leaf; }
  double minKey() const { return nodes_[1].key; }

  /// The smallest key of all leaves but `leaf`: the sibling subtrees along its path.
  double minKeyExcluding(std::size_t leaf) const {
    double best = kNone;
    for (std::size_t n = base_ + leaf; n > 1; n >>= 1) {
      const double sibling = nodes_[n ^ 1].key;
      best = sibling < best ? sibling : best;
    }
    return best;
  }

  /// Calls f(leaf) for every leaf whose key is <= threshold.
  template <class F>
  void forEachAtMost(double threshold, F&& f) const {
    visit(1, threshold, f);
  }

 private:
  static constexpr double kNone = std::numeric_limits<double>::infinity();
  struct Node {
    double key;
    std::uint32_t leaf;
  };

  /// Recomputes inner node n from its children; returns whether it changed.
  bool refresh(std::size_t n) {
    const Node& left = nodes_[2 * n];
    const Node& right = nodes_[2 * n + 1];
    const Node winner = right.key < left.key ? right : left;
    const bool changed = winner.key != nodes_[n].key || winner.leaf != nodes_[n].leaf;
    nodes_[n] = winner;
    return changed;
  }

  template <class F>
  void visit(std::size_t n, double threshold, F& f) const {
    if (!(nodes_[n].key <= threshold)) return;
    if (n >= base_) {
      f(n - base_);
      return;
    }
    visit(2 * n, threshold, f);
    visit(2 * n + 1, threshold, f);
  }

  std::size_t base_ = 1;
  std::vector<Node> nodes_;
};

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
