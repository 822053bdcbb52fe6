#include "viscompm/parallel/communicator.hpp"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <limits>
#include <string>

namespace viscompm::parallel {

Communicator::Communicator(MPI_Comm comm) : comm_(comm) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

double Communicator::sum(double local) const {
  double global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return global;
}

std::int64_t Communicator::sum(std::int64_t local) const {
  std::int64_t global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_INT64_T, MPI_SUM, comm_);
  return global;
}

double Communicator::max(double local) const {
  double global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return global;
}

std::vector<std::int64_t> Communicator::max(const std::vector<std::int64_t>& local) const {
  std::vector<std::int64_t> global(local.size(), 0);
  MPI_Allreduce(local.data(), global.data(), static_cast<int>(local.size()), MPI_INT64_T, MPI_MAX, comm_);
  return global;
}

double Communicator::min(double local) const {
  double global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MIN, comm_);
  return global;
}

std::int64_t Communicator::max(std::int64_t local) const {
  std::int64_t global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_INT64_T, MPI_MAX, comm_);
  return global;
}

namespace {
template <typename T>
std::vector<T> all_gather_values(const std::vector<T>& local, MPI_Datatype type, MPI_Comm comm, int ranks) {
  const int count = static_cast<int>(local.size());
  std::vector<int> counts(ranks), offsets(ranks, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < ranks; ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<T> all(offsets.back() + counts.back());
  MPI_Allgatherv(local.data(), count, type, all.data(), counts.data(), offsets.data(), type, comm);
  return all;
}
}  // namespace

std::vector<double> Communicator::all_gather(const std::vector<double>& local) const {
  return all_gather_values(local, MPI_DOUBLE, comm_, size_);
}

std::vector<std::int64_t> Communicator::all_gather(const std::vector<std::int64_t>& local) const {
  return all_gather_values(local, MPI_INT64_T, comm_, size_);
}

std::vector<std::vector<char>> Communicator::exchange_bytes(const std::vector<const char*>& data,
                                                           const std::vector<std::size_t>& bytes) const {
  std::vector<int> send_counts(size_), recv_counts(size_), send_offsets(size_, 0), recv_offsets(size_, 0);
  for (int r = 0; r < size_; ++r) send_counts[r] = static_cast<int>(bytes[r]);
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm_);
  for (int r = 1; r < size_; ++r) {
    send_offsets[r] = send_offsets[r - 1] + send_counts[r - 1];
    recv_offsets[r] = recv_offsets[r - 1] + recv_counts[r - 1];
  }
  std::vector<char> send_buffer(send_offsets.back() + send_counts.back());
  for (int r = 0; r < size_; ++r)
    if (bytes[r] > 0) std::memcpy(send_buffer.data() + send_offsets[r], data[r], bytes[r]);
  std::vector<char> recv_buffer(recv_offsets.back() + recv_counts.back());
  MPI_Alltoallv(send_buffer.data(), send_counts.data(), send_offsets.data(), MPI_BYTE, recv_buffer.data(),
                recv_counts.data(), recv_offsets.data(), MPI_BYTE, comm_);
  std::vector<std::vector<char>> received(size_);
  for (int r = 0; r < size_; ++r)
    received[r].assign(recv_buffer.begin() + recv_offsets[r], recv_buffer.begin() + recv_offsets[r] + recv_counts[r]);
  return received;
}

bool Communicator::any(bool local) const {
  int value = local ? 1 : 0;
  int global = 0;
  MPI_Allreduce(&value, &global, 1, MPI_INT, MPI_LOR, comm_);
  return global != 0;
}

void Communicator::barrier() const { MPI_Barrier(comm_); }

double machine_memory() {
  double bytes = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGESIZE));
  for (const char* limit_file : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(limit_file);
    double limit = 0.0;
    if (in >> limit && limit > 0.0) bytes = std::min(bytes, limit);
  }
  return bytes;
}

double memory_per_rank(const Communicator& comm) {
  MPI_Comm node;
  MPI_Comm_split_type(comm.comm(), MPI_COMM_TYPE_SHARED, comm.rank(), MPI_INFO_NULL, &node);
  int ranks_here = 1;
  MPI_Comm_size(node, &ranks_here);
  MPI_Comm_free(&node);
  return machine_memory() / ranks_here;
}

double peak_memory() {
  std::ifstream status("/proc/self/status");
  std::string key;
  double kib = 0.0;
  while (status >> key) {
    if (key == "VmHWM:") {
      status >> kib;
      return 1024.0 * kib;
    }
    status.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
  return 0.0;
}

bool reset_peak_memory() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";  // resets VmHWM to the current resident size
  clear.flush();
  return static_cast<bool>(clear);
}

}  // namespace viscompm::parallel
