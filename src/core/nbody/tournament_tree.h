// A tournament (winner) tree over the neighbour pairs: each leaf holds a key (a lower bound
// of the pair's next impact time [s], +inf for none). Leaves come in blocks of eight, one
// cache line each, and a binary tree over the blocks keeps the smallest key of each subtree
// with its leaf. An impact changes three adjacent leaves: one or two blocks are rescanned
// and one walk to the root updates all three, where a binary heap needs three independent
// sifts; the tree over blocks is an eighth of the size of a tree over leaves. Every choice
// is branch-free (the comparisons are unpredictable). Internal to the engine; not installed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

// Internal to the library (and header-only): its calls bind directly, not through the PLT.
#if defined(__GNUC__)
#define CL_NBODY_INTERNAL __attribute__((visibility("hidden")))
#else
#define CL_NBODY_INTERNAL
#endif

namespace collision_lab {
namespace core {
namespace nbody_detail {

class CL_NBODY_INTERNAL TournamentTree {
 public:
  explicit TournamentTree(std::size_t leaves) {
    const std::size_t blocks = (leaves + kBlock - 1) / kBlock;
    base_ = 1;
    while (base_ < blocks) base_ *= 2;
    blocks_.assign(base_, Block{});
    nodes_.assign(2 * base_, Node{kNone, 0});
    rebuild();
  }

  double key(std::size_t leaf) const { return blocks_[leaf / kBlock].key[leaf % kBlock]; }
  /// Sets a leaf without propagating; call update() or rebuild() afterwards.
  void set(std::size_t leaf, double key) { blocks_[leaf / kBlock].key[leaf % kBlock] = key; }

  /// Propagates the leaves first..last (first <= last, any span) to the root. Within two
  /// adjacent blocks (an impact of single bodies) the winner climbs in registers and meets
  /// only the siblings, which are loaded independently: no level waits for the store of the
  /// level below. A wider span (a cluster's impact or merge) refreshes every block in it.
  void update(std::size_t first, std::size_t last) {
    std::size_t lo = base_ + first / kBlock, hi = base_ + last / kBlock;
    if (hi - lo > 1) return updateSpan(lo, hi);
    Node low = blockMinimum(lo - base_);
    nodes_[lo] = low;
    if (hi != lo) {
      Node high = blockMinimum(hi - base_);
      nodes_[hi] = high;
      for (; (lo >> 1) != (hi >> 1); lo >>= 1, hi >>= 1) {
        low = climb(lo, low);
        high = climb(hi, high);
      }
      low = high.key < low.key ? high : low;
      lo >>= 1;
      nodes_[lo] = low;
    }
    for (; lo > 1; lo >>= 1) low = climb(lo, low);
  }

  void rebuild() {
    for (std::size_t b = 0; b < base_; ++b) nodes_[base_ + b] = blockMinimum(b);
    for (std::size_t n = base_ - 1; n >= 1; --n) refresh(n);
  }

  std::size_t minLeaf() const { return nodes_[1].leaf; }
  double minKey() const { return nodes_[1].key; }

  /// The smallest key of all leaves but `leaf`: the rest of its block, then the sibling
  /// subtrees along its block's path. Reduced pairwise and in two chains along the path, not
  /// in one chain of dependent minima (keys are never NaN, so the order does not matter).
  double minKeyExcluding(std::size_t leaf) const {
    const Block& block = blocks_[leaf / kBlock];
    double k[kBlock];
    for (std::size_t j = 0; j < kBlock; ++j) k[j] = j == leaf % kBlock ? kNone : block.key[j];
    double even = least(least(least(k[0], k[1]), least(k[2], k[3])), least(least(k[4], k[5]), least(k[6], k[7])));
    double odd = kNone;
    std::size_t n = base_ + leaf / kBlock;
    for (; n > 3; n >>= 2) {
      even = least(even, nodes_[n ^ 1].key);
      odd = least(odd, nodes_[(n >> 1) ^ 1].key);
    }
    if (n > 1) even = least(even, nodes_[n ^ 1].key);
    return least(even, odd);
  }

  /// Calls f(leaf) for every leaf whose key is <= threshold; an infinite threshold visits
  /// every leaf, the padding ones too (key inf): the caller filters them.
  template <class F>
  void forEachAtMost(double threshold, F&& f) const {
    visit(1, threshold, f);
  }

 private:
  static constexpr std::size_t kBlock = 8;
  static constexpr double kNone = std::numeric_limits<double>::infinity();
  struct alignas(64) Block {
    double key[kBlock] = {kNone, kNone, kNone, kNone, kNone, kNone, kNone, kNone};
  };
  struct Node {
    double key;
    std::uint32_t leaf;
  };

  static double least(double a, double b) { return b < a ? b : a; }

  /// Smallest key of a block and its leaf, by a branch-free knockout; ties go to the lower leaf.
  Node blockMinimum(std::size_t b) const {
    const double* k = blocks_[b].key;
    std::size_t w[4];
    for (std::size_t j = 0; j < 4; ++j) w[j] = 2 * j + static_cast<std::size_t>(k[2 * j + 1] < k[2 * j]);
    const std::size_t x = k[w[1]] < k[w[0]] ? w[1] : w[0];
    const std::size_t y = k[w[3]] < k[w[2]] ? w[3] : w[2];
    const std::size_t z = k[y] < k[x] ? y : x;
    return Node{k[z], static_cast<std::uint32_t>(b * kBlock + z)};
  }

  /// Recomputes inner node n from its children; the winner's address comes from the
  /// comparison, so there is no branch. Ties go to the left child.
  void refresh(std::size_t n) {
    const std::size_t winner = 2 * n + static_cast<std::size_t>(nodes_[2 * n + 1].key < nodes_[2 * n].key);
    nodes_[n] = nodes_[winner];
  }

  /// The winner of node n's parent, given n's winner; stores and returns it. Which of two
  /// equal keys wins does not matter: the engine settles near-ties with precise times.
  Node climb(std::size_t n, const Node& winner) {
    const Node sibling = nodes_[n ^ 1];
    // Selected in registers (a minimum and a conditional move): no branch to mispredict,
    // and no round trip through memory on the path to the root.
    const std::uint32_t sibling_wins = -static_cast<std::uint32_t>(sibling.key < winner.key);  // all ones or 0
    const Node parent{least(winner.key, sibling.key), winner.leaf ^ ((winner.leaf ^ sibling.leaf) & sibling_wins)};
    nodes_[n >> 1] = parent;
    return parent;
  }

  /// update() for block nodes lo..hi more than one apart: the blocks between them changed
  /// too, so every node over the span is recomputed, level by level.
  void updateSpan(std::size_t lo, std::size_t hi) {
    for (std::size_t n = lo; n <= hi; ++n) nodes_[n] = blockMinimum(n - base_);
    while (lo > 1) {
      lo >>= 1, hi >>= 1;
      for (std::size_t n = lo; n <= hi; ++n) refresh(n);
    }
  }

  template <class F>
  void visit(std::size_t n, double threshold, F& f) const {
    if (!(nodes_[n].key <= threshold)) return;
    if (n >= base_) {
      for (std::size_t j = 0; j < kBlock; ++j) {
        if (blocks_[n - base_].key[j] <= threshold) f((n - base_) * kBlock + j);
      }
      return;
    }
    visit(2 * n, threshold, f);
    visit(2 * n + 1, threshold, f);
  }

  std::size_t base_ = 1;       ///< number of block slots, a power of two
  std::vector<Block> blocks_;  ///< the leaves' keys [s], padded with +inf
  std::vector<Node> nodes_;    ///< 1-based: nodes_[1] is the root, [base_, 2 base_) the block minima
};

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
