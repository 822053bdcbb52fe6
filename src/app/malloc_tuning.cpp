#include "viscompm/app/malloc_tuning.hpp"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <unistd.h>

namespace viscompm::app {

std::optional<std::string> huge_page_tunables(const char* glibc_tunables, const char* viscompm_huge_pages) {
  if (viscompm_huge_pages != nullptr && std::strcmp(viscompm_huge_pages, "0") == 0) return std::nullopt;
  const std::string current = glibc_tunables == nullptr ? "" : glibc_tunables;
  if (current.find("glibc.malloc.hugetlb") != std::string::npos) return std::nullopt;
  return current.empty() ? "glibc.malloc.hugetlb=1" : current + ":glibc.malloc.hugetlb=1";
}

void run_with_huge_pages(char** argv) {
#ifdef __GLIBC__
  const auto tunables = huge_page_tunables(std::getenv("GLIBC_TUNABLES"), std::getenv("VISCOMPM_HUGE_PAGES"));
  if (!tunables) return;
  // The program's own file, not /proc/self/exe: the process keeps its name (ps, /proc/PID/comm).
  std::error_code error;
  const std::string program = std::filesystem::read_symlink("/proc/self/exe", error).string();
  if (error || program.empty()) return;
  if (setenv("GLIBC_TUNABLES", tunables->c_str(), 1) != 0) return;
  execv(program.c_str(), argv);
  unsetenv("GLIBC_TUNABLES");  // the exec failed: on as before (setenv copied nothing else)
#else
  (void)argv;
#endif
}

}  // namespace viscompm::app
