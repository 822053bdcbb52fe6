// One HDF5 file holding every stored per-particle quantity (ParticleSet::for_each_field) under
// /particles, written collectively by all ranks (parallel HDF5) to a temporary name renamed when
// complete, and read back by any number of ranks. Frames and checkpoints are such files.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "viscompm/parallel/communicator.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::io {

/// Scalar attributes of the file's root group.
struct FileAttributes {
  std::map<std::string, double> reals;
  std::map<std::string, std::int64_t> integers;
  std::map<std::string, std::string> strings;
  std::map<std::string, std::vector<double>> real_arrays;  ///< small 1D root datasets, same on every rank
};

/// A derived n×3×3 dataset written next to the stored fields (e.g. b^E of (5.5)).
struct DerivedTensor {
  std::string name;
  std::function<Mat3(std::size_t p)> value;
};

/// A small 2D dataset the same on every rank (rank 0 writes it), e.g. a collider surface.
struct Table {
  std::string path;                 ///< "group/name" (the group is created)
  std::size_t columns = 1;
  std::vector<double> reals;        ///< row-major; or
  std::vector<std::int64_t> integers;
};

/// How a particle file is written in pieces, and whether it may be given up between them: each
/// dataset of /particles goes in collective writes of at most `rows` rows per rank, and after each
/// the ranks agree (one collective) on whether a write failed and on `stop`.
struct WritePieces {
  /// Rows per rank in one write (at least 1): 2^20 rows of a 3×3 tensor are 72 MiB, well under a
  /// second on a local disk, so that a stop request is honoured within about that.
  std::int64_t rows = std::int64_t{1} << 20;
  /// This rank's stop request now (a signal number, 0: none), asked after every piece; empty:
  /// the file is written whole (checkpoints, which a stop itself writes).
  std::function<int()> stop;
};

/// Writes `particles` (this rank's rows, in rank order) to `path` (collective), through PATH.tmp
/// renamed when complete, with `tables` (rank 0's rows); returns the global count. If any rank fails to write, every rank throws
/// SimulationError and `path` is left as it was. If any rank's `pieces.stop` asks to stop between
/// two pieces, the partial PATH.tmp is removed and every rank throws StopRequested with the
/// largest signal asked for (`path` left as it was).
std::int64_t write_particle_file(const std::string& path, const FileAttributes& attributes,
                                 const particles::ParticleSet& particles, const std::vector<DerivedTensor>& derived,
                                 const std::string& material_names, const parallel::Communicator& comm,
                                 const std::vector<Table>& tables = {}, const WritePieces& pieces = {});

/// Why writing `path` may have failed: its directory missing or read-only, the disk full, ...
std::string write_failure_reason(const std::string& path);

/// The root attributes and particle count of a file, read without its datasets (any rank alone).
FileAttributes read_file_attributes(const std::string& path, std::int64_t& particle_count);

/// Reads every stored field; rank r gets the r-th of `comm.size()` contiguous slices of rows.
/// Throws InputError if the file cannot be read or lacks a field.
particles::ParticleSet read_particle_file(const std::string& path, const parallel::Communicator& comm,
                                          FileAttributes& attributes);

}  // namespace viscompm::io
