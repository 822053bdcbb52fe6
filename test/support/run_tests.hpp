// The part of every test main after start-up: checks the rank count the test was registered for
// (--ranks=N from CMake), so that no MPI test passes at the wrong count, prints results on rank 0
// only, and fails on every rank if a test failed on any.
#pragma once

#include <gtest/gtest.h>
#include <mpi.h>

#include <cstdlib>
#include <cstring>
#include <iostream>

namespace viscompm::testkit {

inline int run_tests(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  int expected = -1;
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], "--ranks=", 8) == 0) expected = std::atoi(argv[i] + 8);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (expected > 0 && expected != size) {
    if (rank == 0) std::cerr << "registered for " << expected << " ranks, running on " << size << "\n";
    return 1;
  }
  if (rank != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  int failed = RUN_ALL_TESTS();
  int any_failed = 0;
  MPI_Allreduce(&failed, &any_failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return any_failed;
}

}  // namespace viscompm::testkit
