// Initialises MPI and Kokkos for the whole program (Tpetra::ScopeGuard), and finalises them when
// it goes out of scope. Construct one at the top of main.
#pragma once

#include <memory>

namespace viscompm::linalg {

class Environment {
 public:
  Environment(int* argc, char*** argv);
  ~Environment();
  Environment(const Environment&) = delete;
  Environment& operator=(const Environment&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viscompm::linalg
