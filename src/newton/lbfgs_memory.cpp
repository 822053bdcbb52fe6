#include "viscompm/newton/lbfgs_memory.hpp"

#include <cmath>
#include <vector>

namespace viscompm::newton {

namespace {
// a += c b
void add_scaled(NodeVectorField& a, double c, const NodeVectorField& b) {
  for (std::size_t i = 0; i < a.size(); ++i) a[i] += c * b[i];
}
}  // namespace

bool LbfgsMemory::add(NodeVectorField s, NodeVectorField y, const Dot& dot) {
  const double sy = dot(s, y);
  const double ss = dot(s, s), yy = dot(y, y);
  // Curvature condition with a relative margin: rounding must not make H indefinite.
  if (!(sy > 1e-12 * std::sqrt(ss * yy))) return false;
  if (static_cast<int>(pairs_.size()) == capacity_) pairs_.pop_front();
  pairs_.push_back({std::move(s), std::move(y), 1.0 / sy});
  return true;
}

void LbfgsMemory::direction(const NodeVectorField& g, NodeVectorField& d, const Dot& dot,
                            const InitialInverse& initial, bool scale) const {
  // Two-loop recursion (Nocedal & Wright, Algorithm 7.4) on q = −g.
  NodeVectorField q(g.size());
  for (std::size_t i = 0; i < g.size(); ++i) q[i] = -g[i];
  std::vector<double> alpha(pairs_.size());
  for (std::size_t k = pairs_.size(); k-- > 0;) {
    alpha[k] = pairs_[k].rho * dot(pairs_[k].s, q);
    add_scaled(q, -alpha[k], pairs_[k].y);
  }
  initial(q, d);
  if (scale && !pairs_.empty()) {
    const Pair& newest = pairs_.back();
    const double gamma = 1.0 / (newest.rho * dot(newest.y, newest.y));
    for (auto& x : d) x *= gamma;
  }
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const double beta = pairs_[k].rho * dot(pairs_[k].y, d);
    add_scaled(d, alpha[k] - beta, pairs_[k].s);
  }
}

}  // namespace viscompm::newton
