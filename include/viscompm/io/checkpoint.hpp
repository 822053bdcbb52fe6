// Checkpoints: the whole state of a run (every stored particle quantity, time, step, frame
// counter, the Δt controller's cap) in one parallel HDF5 file, DIR/checkpoint_NNNNN.h5 (frame
// number), written to a temporary name and renamed when complete. Colliders are functions of
// time and nothing in a run is random, so that is all a restart needs. A checkpoint written on
// any number of ranks restarts on any other.
#pragma once

#include <cstdint>
#include <string>

#include "viscompm/materials/material.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::io {

struct RunState {
  double time = 0.0;
  std::int64_t step = 0;
  int frame = 0;
  double time_step_cap = 0.0;
  std::string scene;  ///< the scene's name, checked on restart
  /// The decomposition's boxes (6 numbers per rank: lower, upper) when it is not the initial
  /// block one, so that a restart on the same rank count continues bit for bit.
  std::vector<double> decomposition_boxes;
  /// Layers each emitter has emitted (its next ids and the mass it delivered follow).
  std::vector<double> emitter_layers;
};

std::string checkpoint_file_name(int frame);

/// Writes DIR/checkpoint_NNNNN.h5 (collective) and returns its path.
std::string write_checkpoint(const std::string& directory, const RunState& state, const particles::ParticleSet& particles,
                             const materials::MaterialList& materials, const parallel::Communicator& comm);

/// Reads a checkpoint: rank r gets a contiguous share of the particles (the caller migrates them
/// to their owners). Throws InputError if it is not a readable viscompm checkpoint.
particles::ParticleSet read_checkpoint(const std::string& path, const parallel::Communicator& comm, RunState& state,
                                       std::string& material_names);

}  // namespace viscompm::io
