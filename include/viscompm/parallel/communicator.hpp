// A thin value wrapper around an MPI communicator: rank, size and the few collectives the
// physics layer needs (global sums of energies, maxima of speeds, agreement on decisions, gathers).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <cstring>
#include <type_traits>
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
  /// The element-wise maximum over the ranks of equally long vectors, on every rank: several
  /// decisions agreed in one collective (e.g. a run's stop state after a step).
  std::vector<std::int64_t> max(const std::vector<std::int64_t>& local) const;
  /// Every rank's values, concatenated in rank order, on every rank.
  std::vector<double> all_gather(const std::vector<double>& local) const;
  std::vector<std::int64_t> all_gather(const std::vector<std::int64_t>& local) const;
  /// Personalised exchange: outgoing[r] goes to rank r (outgoing has size() entries); returns
  /// what every rank sent to this one, by source rank. Collective; T must be trivially copyable.
  template <class T>
  std::vector<std::vector<T>> exchange(const std::vector<std::vector<T>>& outgoing) const;
  /// True on every rank if `local` is true on any rank.
  bool any(bool local) const;
  void barrier() const;

 private:
  /// Byte-level exchange behind exchange<T>.
  std::vector<std::vector<char>> exchange_bytes(const std::vector<const char*>& data,
                                                const std::vector<std::size_t>& bytes) const;

  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
};

/// The memory of this machine in bytes, or its control group's limit (batch systems) if lower.
double machine_memory();
/// The memory each rank of `comm` may use: the machine's, shared among the ranks on it (collective).
double memory_per_rank(const Communicator& comm);
/// This process's peak resident memory in bytes since it started or since the last
/// reset_peak_memory() (Linux: VmHWM of /proc/self/status; 0 where unknown).
double peak_memory();
/// Starts a new peak-memory measurement for this process (Linux: /proc/self/clear_refs); false
/// where that is not possible, and peak_memory() then counts from the start of the process.
bool reset_peak_memory();

template <class T>
std::vector<std::vector<T>> Communicator::exchange(const std::vector<std::vector<T>>& outgoing) const {
  static_assert(std::is_trivially_copyable_v<T>);
  std::vector<const char*> data(size_);
  std::vector<std::size_t> bytes(size_);
  for (int r = 0; r < size_; ++r) {
    data[r] = reinterpret_cast<const char*>(outgoing[r].data());
    bytes[r] = outgoing[r].size() * sizeof(T);
  }
  const auto received = exchange_bytes(data, bytes);
  std::vector<std::vector<T>> incoming(size_);
  for (int r = 0; r < size_; ++r) {
    incoming[r].resize(received[r].size() / sizeof(T));
    if (!received[r].empty()) std::memcpy(static_cast<void*>(incoming[r].data()), received[r].data(), received[r].size());
  }
  return incoming;
}

}  // namespace viscompm::parallel
