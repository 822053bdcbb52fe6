// GoogleTest main of the physics tests (grid, particles, materials, transfer, boundary,
// implicit/incremental_potential, parallel): MPI only, linked against libviscompm_physics alone.
#include "run_tests.hpp"

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  const int result = viscompm::testkit::run_tests(argc, argv);
  MPI_Finalize();
  return result;
}
