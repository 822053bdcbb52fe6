// Emitters: a nozzle (box, cylinder or disc) that injects particles of one material at a
// prescribed velocity and mass rate between a start and a stop time. Each emission is a layer of
// particles on a lattice of spacing h = Δx / n (n per cell and dimension) in the nozzle's
// cross-section through its centre, normal to the velocity; particles have volume h³. Layer k
// leaves at t_k = start + k·τ with τ = (layer mass) / (mass rate), so the delivered mass is the
// rate times the elapsed time to within one layer, and is placed at x₀ + v (t − t_k) when a step
// starts at t ≥ t_k. Ids are base + k·stride + offset + j (j: the site in the layer): unique
// across emitters, ranks and restarts, and independent of the rank count. The nozzle's grid
// nodes get the inflow velocity in the solve (boundary::Inflow).
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "viscompm/core/shape.hpp"
#include "viscompm/grid/grid_geometry.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::particles {

struct EmitterSpec {
  std::string name;
  Shape nozzle;                    ///< box or cylinder (a disc is a short cylinder)
  Vec3 velocity = Vec3::UnitX();   ///< inflow velocity [m/s], non-zero
  double mass_rate = 0.0;          ///< [kg/s]; 0: ρ·(cross-section)·|v|, a continuous stream
  double start_time = 0.0;
  double stop_time = std::numeric_limits<double>::infinity();
  int particles_per_cell = 2;
  int material_id = 0;
  double density = 1.0;
};

class Emitter {
 public:
  /// `id_base`, `id_stride`, `id_offset`: layer k's site j gets id base + k·stride + offset + j.
  Emitter(const EmitterSpec& spec, const grid::GridGeometry& grid, ParticleId id_base, ParticleId id_stride,
          ParticleId id_offset);

  /// Adds the layers due by time t (t_k ≤ t, t_k < stop) whose particles satisfy keep(x);
  /// every rank counts every layer. Returns the number of particles added on this rank.
  std::size_t emit(double t, const std::function<bool(const Vec3&)>& keep, ParticleSet& particles);

  const EmitterSpec& spec() const { return spec_; }
  /// Sites per layer.
  std::size_t layer_size() const { return sites_.size(); }
  double particle_mass() const { return particle_mass_; }
  double layer_interval() const { return layer_interval_; }
  /// Layers emitted so far (the state a checkpoint keeps).
  std::int64_t layers_emitted() const { return layers_; }
  void set_layers_emitted(std::int64_t layers) { layers_ = layers; }
  /// Mass emitted so far, summed over all ranks.
  double delivered_mass() const { return static_cast<double>(layers_) * layer_size() * particle_mass_; }

 private:
  EmitterSpec spec_;
  std::vector<Vec3> sites_;  ///< positions of one layer at its emission time
  double particle_volume_ = 0.0, particle_mass_ = 0.0, layer_interval_ = 0.0;
  ParticleId id_base_ = 0, id_stride_ = 0, id_offset_ = 0;
  std::int64_t layers_ = 0;
};

/// The sites of one layer: lattice points of spacing h in the plane through the nozzle's centre
/// normal to `direction`, inside the nozzle.
std::vector<Vec3> nozzle_sites(const Shape& nozzle, const Vec3& direction, double h);

}  // namespace viscompm::particles
