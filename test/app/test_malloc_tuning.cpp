// The programs run with glibc's malloc asking for transparent huge pages (app/malloc_tuning):
// the tunable is added to what the user set, never twice, and not at all when turned off.
#include <gtest/gtest.h>

#include "viscompm/app/malloc_tuning.hpp"

using viscompm::app::huge_page_tunables;

TEST(MallocTuning, AddsTheHugePageTunableToWhatTheUserSet) {
  EXPECT_EQ(huge_page_tunables(nullptr, nullptr), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(huge_page_tunables("", nullptr), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(huge_page_tunables("glibc.malloc.arena_max=2", nullptr), "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1");
  EXPECT_EQ(huge_page_tunables(nullptr, "1"), "glibc.malloc.hugetlb=1");
}

TEST(MallocTuning, LeavesAChosenValueAndAnOptOutAlone) {
  // Already set (by the user, or by the program's first execution: no second re-execution).
  EXPECT_FALSE(huge_page_tunables("glibc.malloc.hugetlb=0", nullptr));
  EXPECT_FALSE(huge_page_tunables("glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1", nullptr));
  EXPECT_FALSE(huge_page_tunables(nullptr, "0"));
  EXPECT_FALSE(huge_page_tunables("glibc.malloc.arena_max=2", "0"));
}
