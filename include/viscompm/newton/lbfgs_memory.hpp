// The memory of L-BFGS (Nocedal & Wright, Algorithm 7.4): the last pairs of steps s_k and
// gradient changes y_k, and the two-loop recursion that applies the inverse-Hessian
// approximation they define on top of an initial one. Plain algebra on node fields; the dot
// product (global, over owned nodes) and the initial inverse Hessian are the caller's.
#pragma once

#include <deque>
#include <functional>

#include "viscompm/core/types.hpp"

namespace viscompm::newton {

class LbfgsMemory {
 public:
  using Dot = std::function<double(const NodeVectorField&, const NodeVectorField&)>;
  /// z = H₀ r (an SPD approximation of the inverse Hessian, e.g. one multigrid cycle).
  using InitialInverse = std::function<void(const NodeVectorField& r, NodeVectorField& z)>;

  explicit LbfgsMemory(int pairs) : capacity_(pairs) {}

  /// Keeps (s, y) if its curvature s·y is positive (else H would lose definiteness); the oldest
  /// pair goes when the memory is full. Returns whether the pair was kept.
  bool add(NodeVectorField s, NodeVectorField y, const Dot& dot);
  /// d = −H g by the two-loop recursion, H the L-BFGS inverse Hessian on top of `initial`; with
  /// `scale`, `initial` is scaled by s·y / y·y of the newest pair (for an unscaled H₀ = I).
  void direction(const NodeVectorField& g, NodeVectorField& d, const Dot& dot, const InitialInverse& initial,
                 bool scale) const;
  void clear() { pairs_.clear(); }
  int size() const { return static_cast<int>(pairs_.size()); }

 private:
  struct Pair {
    NodeVectorField s, y;
    double rho;  // 1 / (y·s)
  };
  int capacity_;
  std::deque<Pair> pairs_;  // oldest first
};

}  // namespace viscompm::newton
