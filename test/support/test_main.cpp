// GoogleTest main of the tests that use Trilinos (linalg, scene, implicit/newton, simulation,
// io, study): starts MPI and Kokkos through linalg::Environment.
#include "run_tests.hpp"
#include "viscompm/linalg/environment.hpp"

int main(int argc, char** argv) {
  viscompm::linalg::Environment environment(&argc, &argv);
  return viscompm::testkit::run_tests(argc, argv);
}
