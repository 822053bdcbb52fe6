#include "viscompm/linalg/environment.hpp"

#include <Tpetra_Core.hpp>
#include <cstring>
#include <vector>

namespace viscompm::linalg {

struct Environment::Impl {
  // Kokkos answers --help itself (on every rank): it sees the arguments without it.
  Impl(int argc, char** argv) {
    for (int i = 0; i < argc; ++i)
      if (std::strcmp(argv[i], "--help") != 0 && std::strcmp(argv[i], "-h") != 0) arguments.push_back(argv[i]);
    count = static_cast<int>(arguments.size());
    arguments.push_back(nullptr);
    pointer = arguments.data();
    guard = std::make_unique<Tpetra::ScopeGuard>(&count, &pointer);
  }
  std::vector<char*> arguments;
  int count = 0;
  char** pointer = nullptr;
  std::unique_ptr<Tpetra::ScopeGuard> guard;
};

Environment::Environment(int* argc, char*** argv) : impl_(std::make_unique<Impl>(*argc, *argv)) {}
Environment::~Environment() = default;

}  // namespace viscompm::linalg
