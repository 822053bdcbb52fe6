// glibc's malloc and transparent huge pages. At Table 5.1's size every Newton step refills
// matrices, hierarchies and Krylov vectors of hundreds of MB that malloc maps anew, page by 4 KiB
// page (21 million page faults in the pie's frame at Δx 0.0024 on 2 ranks). With the glibc
// tunable glibc.malloc.hugetlb=1 malloc asks the kernel for transparent huge pages for them
// (doc/performance.md). The tunable is read only when a process starts, so the programs execute
// themselves once more with it set, before anything else (MPI included); VISCOMPM_HUGE_PAGES=0
// turns that off, and a GLIBC_TUNABLES that already says glibc.malloc.hugetlb is left as it is.
#pragma once

#include <optional>
#include <string>

namespace viscompm::app {

/// The GLIBC_TUNABLES value to run with, given the current one and VISCOMPM_HUGE_PAGES (either
/// may be null); nullopt when nothing is to change.
std::optional<std::string> huge_page_tunables(const char* glibc_tunables, const char* viscompm_huge_pages);

/// Re-executes the program (the file /proc/self/exe names, so that the process keeps its name;
/// the same argv) with huge_page_tunables() in its
/// environment when it changes anything and glibc is the C library; returns if it does not (or
/// the exec fails: the run goes on without).
void run_with_huge_pages(char** argv);

}  // namespace viscompm::app
