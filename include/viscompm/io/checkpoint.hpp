// Checkpoints: the whole state of a run (every stored particle quantity, time, step, frame
// counter, the Δt controller's cap, the decomposition) in one parallel HDF5 file, written to a
// temporary name and renamed when complete: DIR/checkpoint_NNNNN.h5 at frame NNNNN, or
// DIR/checkpoint_step_SSSSSSSS.h5 after step SSSSSSSS inside a frame (a stop requested by a
// signal, or Output/Checkpoint wall seconds). Colliders are functions of time and nothing in a
// run is random, so that is all a restart needs. A checkpoint written on any number of ranks
// restarts on any other (doc/contracts.md).
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
  /// The particle imbalance the last re-partition reached (rebalancing decisions depend on it).
  double balanced_imbalance = 1.0;
};

/// checkpoint_NNNNN.h5: the checkpoint of frame `frame`.
std::string checkpoint_file_name(int frame);
/// checkpoint_step_SSSSSSSS.h5: a checkpoint after step `step`, between frames.
std::string step_checkpoint_file_name(std::int64_t step);

/// Writes the checkpoint `path` (collective; SimulationError if any rank fails, `path` untouched).
void write_checkpoint(const std::string& path, const RunState& state, const particles::ParticleSet& particles,
                      const materials::MaterialList& materials, const parallel::Communicator& comm);

/// Reads a checkpoint: rank r gets a contiguous share of the particles (the caller migrates them
/// to their owners). Throws InputError if it is not a readable viscompm checkpoint, or holds
/// values no run can have written (non-finite numbers, unknown materials, negative masses).
particles::ParticleSet read_checkpoint(const std::string& path, const parallel::Communicator& comm, RunState& state,
                                       std::string& material_names);

}  // namespace viscompm::io
