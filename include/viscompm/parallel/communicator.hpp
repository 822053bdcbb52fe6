// A thin value wrapper around an MPI communicator: rank, size and the few collectives the
// physics layer needs (global sums of energies, maxima of speeds, agreement on decisions, gathers).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <vector>

namespace viscompm::parallel {

class Communicator {
 public:
  explicit Communicator(MPI_Comm comm = MPI_COMM_WORLD);

  MPI_Comm comm() const { return comm_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }

  double sum(double local) const;
  std::int64_t sum(std::int64_t local) const;
  double max(double local) const;
  double min(double local) const;
  std::int64_t max(std::int64_t local) const;
  /// Every rank's values, concatenated in rank order, on every rank.
  std::vector<double> all_gather(const std::vector<double>& local) const;
  std::vector<std::int64_t> all_gather(const std::vector<std::int64_t>& local) const;
  /// True on every rank if `local` is true on any rank.
  bool any(bool local) const;
  void barrier() const;

 private:
  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
};

}  // namespace viscompm::parallel
