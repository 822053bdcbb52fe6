// The constitutive-model interface. A particle's potential is a function of one 3x3 matrix,
// A_p = Σ_i (x̂_i − x_i)(∇w_ip)^T (Appendix A), through which every strain a model stores is
// predicted: F̂ = (I + A) F^n (5.12), Ŝ(A) (5.14 or §4.6), ε̂ = sym(A)/Δt. A model computes
// its cached quantities once per call, then the energy, gradient and Hessian from them.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "viscompm/core/types.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::materials {

struct StepContext {
  double dt = 0.0;  ///< Δt of the step being solved
};

/// Φ_p(A) = V_p^0 Ψ_p and its derivatives with respect to vec(A) (column-major, see vec()).
struct PotentialDerivatives {
  double energy = 0.0;
  Mat3 gradient = Mat3::Zero();  ///< ∂Φ_p/∂A
  Mat9 hessian = Mat9::Zero();   ///< ∂²Φ_p/∂vec(A)², not yet projected
};

class Material {
 public:
  explicit Material(std::string name) : name_(std::move(name)) {}
  virtual ~Material() = default;

  /// The scene's name for this material (e.g. "sponge").
  const std::string& name() const { return name_; }
  /// The model's registry name (e.g. "oldroyd_b").
  virtual std::string model() const = 0;
  virtual double density() const = 0;
  /// Speed of the fastest elastic wave, √((λ + 2μ)/ρ), for time-step diagnostics.
  virtual double wave_speed() const = 0;
  /// The per-particle fields (ParticleSet / HDF5 dataset names) this model's state lives in:
  /// what evaluate reads and update_state writes, besides position, velocity, mass and volume.
  virtual std::vector<std::string> state_fields() const = 0;

  /// Evaluates Φ_p(A) and, for order ≥ 1, its gradient and, for order 2, its Hessian.
  /// Returns false (and leaves `out` unspecified) if A makes the particle's state infeasible:
  /// the line search then treats the energy as +∞ (§5.7).
  virtual bool evaluate(const particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                        const StepContext& step, int order, PotentialDerivatives& out) const = 0;

  /// After the solve: stores the strains predicted by the final A (the same maps as evaluate),
  /// then applies the model's explicit plastic correction if it has one (§4.4, §4.3: the return
  /// mappings of svd_plasticity and von_mises act after the solve, as in Stomakhin et al. 2013).
  virtual void update_state(particles::ParticleSet& particles, std::size_t p, const Mat3& A,
                            const StepContext& step) const = 0;

  /// b^E of (5.5) for output: the elastic left Cauchy-Green strain the stress is computed from.
  virtual Mat3 left_cauchy_green_elastic(const particles::ParticleSet& particles, std::size_t p) const = 0;

 private:
  std::string name_;
};

using MaterialList = std::vector<std::unique_ptr<Material>>;

}  // namespace viscompm::materials
