// The output of a run (doc/contracts.md): DIR/frame_NNNNN.h5 (one file per frame whatever the rank count,
// written collectively with parallel HDF5, to a temporary name renamed when complete) and
// DIR/particles.xdmf, the index ParaView opens.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "viscompm/io/particle_file.hpp"
#include "viscompm/materials/material.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::io {

struct FrameInfo {
  int frame = 0;
  double time = 0.0;
  std::int64_t step = 0;
  std::int64_t particle_count = 0;  ///< global; filled by write_frame
  std::int64_t collider_vertices = 0;   ///< of /colliders (0: no colliders in the frame)
  std::int64_t collider_triangles = 0;
};

/// What a frame holds besides the particles: the colliders' surfaces at the frame's time
/// (/colliders/{vertices, triangles, collider_id}) and the mass the emitters delivered so far
/// (root attribute emitted_mass).
struct FrameExtras {
  std::vector<double> collider_vertices;        ///< n × 3, row-major
  std::vector<std::int64_t> collider_triangles; ///< m × 3 vertex indices
  std::vector<std::int64_t> collider_id;        ///< per triangle: the collider's index in the scene
  double emitted_mass = 0.0;
};

std::string frame_file_name(int frame);

/// Writes DIR/frame_NNNNN.h5 collectively: every field of ParticleSet::for_each_field under
/// /particles (plus left_cauchy_green_elastic from each material). Rows are in rank order;
/// `id` identifies particles.
/// Returns the frame's info with the global particle count. Written in `pieces`, between which
/// a stop request removes the partial file and throws StopRequested on every rank
/// (write_particle_file).
FrameInfo write_frame(const std::string& directory, FrameInfo info, const particles::ParticleSet& particles,
                      const materials::MaterialList& materials, const parallel::Communicator& comm,
                      const FrameExtras& extras = {}, const WritePieces& pieces = {});

/// The material names in material_id order, comma-separated (an attribute of /particles).
std::string material_names(const materials::MaterialList& materials);

/// Rewrites DIR/particles.xdmf for `frames` (rank 0 only; temporary name, then rename, so that a
/// failed write leaves the previous index). Throws SimulationError if it cannot be written.
void write_xdmf(const std::string& directory, const std::vector<FrameInfo>& frames);

}  // namespace viscompm::io
