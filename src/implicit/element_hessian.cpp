#include "viscompm/implicit/element_hessian.hpp"

#include <algorithm>

namespace viscompm::implicit {

ElementHessian::ElementHessian(int nodes_per_cell)
    : nodes_(nodes_per_cell),
      lanes_((nodes_per_cell + 3) / 4 * 4),
      element_(static_cast<std::size_t>(nodes_per_cell) * 9 * lanes_, 0.0),
      stage_(27 * static_cast<std::size_t>(lanes_), 0.0),
      gradients_(3 * static_cast<std::size_t>(lanes_), 0.0) {}

void ElementHessian::clear() { std::fill(element_.begin(), element_.end(), 0.0); }

namespace {
// The two stages for a fixed lane count L (a compile-time constant, so the lane loops vectorise).
template <int L>
[[gnu::always_inline]] inline void add_particle_lanes(int nodes, const Mat9& h, double* __restrict element, double* __restrict stage,
                        const double* __restrict dw) {
  const double* dwx = dw;
  const double* dwy = dw + L;
  const double* dwz = dw + 2 * L;
  // Per node j: G_j[β](σ, τ) = Σ_κ H(σ+3β, τ+3κ) ∇w_j[κ].
  for (int beta = 0; beta < 3; ++beta)
    for (int sigma = 0; sigma < 3; ++sigma)
      for (int tau = 0; tau < 3; ++tau) {
        const int row = 3 * beta + sigma;
        const double h0 = h(row, tau), h1 = h(row, tau + 3), h2 = h(row, tau + 6);
        double* g = stage + (9 * beta + 3 * sigma + tau) * L;
        for (int j = 0; j < L; ++j) g[j] = h0 * dwx[j] + h1 * dwy[j] + h2 * dwz[j];
      }
  // Per node pair i ≤ j: E(iσ, jτ) += Σ_β ∇w_i[β] G_j[β](σ, τ), from the lane block holding i.
  for (int i = 0; i < nodes; ++i) {
    const double a = dwx[i], b = dwy[i], c = dwz[i];
    const int first = i & ~3;
    for (int st = 0; st < 9; ++st) {
      double* e = element + (static_cast<std::size_t>(i) * 9 + st) * L;
      const double* g0 = stage + st * L;
      const double* g1 = stage + (9 + st) * L;
      const double* g2 = stage + (18 + st) * L;
      for (int j = first; j < L; ++j) e[j] += a * g0[j] + b * g1[j] + c * g2[j];
    }
  }
}
// The assembly's hottest loop, compiled twice: for AVX2 with FMA (x86-64-v3, four lanes a
// vector), chosen at load time where the processor has it, and for the baseline x86-64 (two).
[[gnu::target_clones("arch=x86-64-v3", "default")]] void add_particle_28(int nodes, const Mat9& h, double* element,
                                                                          double* stage, const double* dw) {
  add_particle_lanes<28>(nodes, h, element, stage, dw);
}
[[gnu::target_clones("arch=x86-64-v3", "default")]] void add_particle_64(int nodes, const Mat9& h, double* element,
                                                                          double* stage, const double* dw) {
  add_particle_lanes<64>(nodes, h, element, stage, dw);
}
}  // namespace

void ElementHessian::add_particle(const Mat9& h, const Vec3* dw) {
  for (int j = 0; j < nodes_; ++j)
    for (int beta = 0; beta < 3; ++beta) gradients_[beta * lanes_ + j] = dw[j][beta];
  switch (lanes_) {
    case 28: add_particle_28(nodes_, h, element_.data(), stage_.data(), gradients_.data()); break;
    case 64: add_particle_64(nodes_, h, element_.data(), stage_.data(), gradients_.data()); break;
    default: {
      // Any other stencil: the same stages without a compile-time lane count.
      for (int beta = 0; beta < 3; ++beta)
        for (int sigma = 0; sigma < 3; ++sigma)
          for (int tau = 0; tau < 3; ++tau) {
            const int row = 3 * beta + sigma;
            double* g = stage_.data() + (9 * beta + 3 * sigma + tau) * lanes_;
            for (int j = 0; j < lanes_; ++j)
              g[j] = h(row, tau) * gradients_[j] + h(row, tau + 3) * gradients_[lanes_ + j] +
                     h(row, tau + 6) * gradients_[2 * lanes_ + j];
          }
      for (int i = 0; i < nodes_; ++i)
        for (int st = 0; st < 9; ++st)
          for (int j = i; j < lanes_; ++j)
            element_[(static_cast<std::size_t>(i) * 9 + st) * lanes_ + j] +=
                gradients_[i] * stage_[st * lanes_ + j] + gradients_[lanes_ + i] * stage_[(9 + st) * lanes_ + j] +
                gradients_[2 * lanes_ + i] * stage_[(18 + st) * lanes_ + j];
    }
  }
}

Mat3 ElementHessian::block(int i, int j) const {
  Mat3 b;
  for (int sigma = 0; sigma < 3; ++sigma)
    for (int tau = 0; tau < 3; ++tau) b(sigma, tau) = entry(i, j, sigma, tau);
  return b;
}

}  // namespace viscompm::implicit
