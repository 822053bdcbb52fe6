// The measured choice between solver configurations (newton::SolverChoice): it picks the cheapest
// per step, re-measures on a doubling schedule, follows a regime change, and costs little more
// than the best fixed choice.
#include <gtest/gtest.h>

#include <functional>

#include "viscompm/newton/solver_choice.hpp"

using viscompm::linalg::SolverChoiceSettings;
using viscompm::newton::SolverChoice;

namespace {
// Runs `steps` steps where candidate c costs cost(c, step); returns the total cost.
double run(SolverChoice& choice, int steps, const std::function<double(int, int)>& cost, int first_step = 0) {
  double total = 0.0;
  for (int step = first_step; step < first_step + steps; ++step) {
    const double seconds = cost(choice.next(), step);
    total += seconds;
    choice.solved(seconds);
  }
  return total;
}
}  // namespace

TEST(SolverChoice, TriesEachCandidateThenKeepsTheCheapest) {
  SolverChoice choice(2, SolverChoiceSettings{});
  EXPECT_EQ(choice.next(), 0);
  choice.solved(3.0);
  EXPECT_EQ(choice.next(), 1);
  choice.solved(1.0);
  EXPECT_EQ(choice.chosen(), 1);
  EXPECT_EQ(choice.trials(), 1);
  // Until the first recheck (16 steps), the cheaper one solves every step.
  for (int k = 0; k < 15; ++k) {
    EXPECT_EQ(choice.next(), 1);
    choice.solved(1.0);
  }
  choice.solved(1.0);  // the 16th: the recheck is due
  EXPECT_EQ(choice.next(), 0) << "the other candidate is measured again";
  choice.solved(3.0);
  EXPECT_EQ(choice.next(), 1);
  EXPECT_EQ(choice.trials(), 2);
  EXPECT_EQ(choice.switches(), 0);
}

TEST(SolverChoice, ConfirmedChoicesAreRecheckedOnADoublingSchedule) {
  SolverChoice choice(2, SolverChoiceSettings{});
  std::vector<int> trial_systems;  // the steps at which the expensive candidate ran
  for (int step = 0; step < 2000; ++step) {
    if (choice.next() == 0) trial_systems.push_back(step);
    choice.solved(choice.next() == 0 ? 5.0 : 1.0);
  }
  // Step 0 (the first trial), then after 16, 32, 64, 128, 256, 256, ... steps of the chosen one.
  ASSERT_GE(trial_systems.size(), 7u);
  std::vector<int> gaps;
  for (std::size_t k = 1; k < trial_systems.size(); ++k) gaps.push_back(trial_systems[k] - trial_systems[k - 1] - 1);
  EXPECT_EQ(gaps[0], 17);  // the first trial's step of candidate 1, then 16 of it
  EXPECT_EQ(gaps[1], 32);
  EXPECT_EQ(gaps[2], 64);
  EXPECT_EQ(gaps[3], 128);
  EXPECT_EQ(gaps[4], 256);
  EXPECT_EQ(gaps[5], 256);
}

TEST(SolverChoice, CostsAtMostAFewPercentMoreThanTheBestFixedChoice) {
  // Over 1000 steps, candidates 3× apart, in either order: within 5 % of the cheaper one alone.
  for (const double first : {1.0, 3.0}) {
    SolverChoice choice(2, SolverChoiceSettings{});
    const double total = run(choice, 1000, [first](int c, int) { return c == 0 ? first : 4.0 - first; });
    EXPECT_LE(total, 1.05 * 1000.0) << "first candidate costs " << first;
    EXPECT_GT(total, 1000.0);
  }
}

TEST(SolverChoice, FollowsARegimeChange) {
  // The pie: a soft flight where candidate 0 (the paper's solver) is 3× cheaper, then an impact
  // from step 100 on where it becomes 10× dearer than candidate 1 (the multigrid).
  auto cost = [](int c, int step) {
    if (step < 100) return c == 0 ? 1.0 : 3.0;
    return c == 0 ? 20.0 : 2.0;
  };
  SolverChoice choice(2, SolverChoiceSettings{});
  const double flight = run(choice, 100, cost);
  EXPECT_EQ(choice.chosen(), 0);
  const double impact = run(choice, 200, cost, 100);
  EXPECT_EQ(choice.chosen(), 1);
  EXPECT_EQ(choice.switches(), 1);
  // The change is noticed within Regime steps + a trial, not at the next scheduled recheck:
  // the total is within 5 % of the best choice in each regime, plus those few steps.
  const double best = 100.0 * 1.0 + 200.0 * 2.0;
  EXPECT_LE(flight + impact, best + 0.05 * best + 5 * 20.0);
  // Both fixed choices cost more.
  EXPECT_LT(flight + impact, 100.0 * 3.0 + 200.0 * 2.0);
  EXPECT_LT(flight + impact, 100.0 * 1.0 + 200.0 * 20.0);
}

TEST(SolverChoice, NoiseBelowTheRegimeFactorTriggersNoTrial) {
  // The chosen one's steps vary by ±40 % around 1 (Newton iterations per step vary): with
  // Regime change 2 that is no regime change, so trials come only on schedule.
  SolverChoice choice(2, SolverChoiceSettings{});
  run(choice, 1000, [](int c, int step) { return c == 0 ? 1.0 + 0.4 * ((step % 3) - 1) : 4.0; });
  EXPECT_EQ(choice.chosen(), 0);
  EXPECT_LE(choice.trials(), 1 + 6);  // the first, then after 16, 32, 64, 128, 256, 256 steps
  EXPECT_EQ(choice.switches(), 0);
}

TEST(SolverChoice, ThreeCandidatesAndLongerTrials) {
  SolverChoiceSettings settings;
  settings.trial_systems = 2;
  SolverChoice choice(3, settings);
  std::vector<int> order;
  for (int k = 0; k < 6; ++k) {
    order.push_back(choice.next());
    choice.solved(choice.next() == 2 ? 1.0 : 2.0);
  }
  EXPECT_EQ(order, (std::vector<int>{0, 0, 1, 1, 2, 2}));
  EXPECT_EQ(choice.chosen(), 2);
  EXPECT_EQ(choice.systems(), (std::vector<int>{2, 2, 2}));
}
