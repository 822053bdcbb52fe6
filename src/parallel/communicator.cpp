#include "viscompm/parallel/communicator.hpp"

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

bool Communicator::any(bool local) const {
  int value = local ? 1 : 0;
  int global = 0;
  MPI_Allreduce(&value, &global, 1, MPI_INT, MPI_LOR, comm_);
  return global != 0;
}

void Communicator::barrier() const { MPI_Barrier(comm_); }

}  // namespace viscompm::parallel
