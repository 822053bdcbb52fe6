// The measured choice between solver configurations (newton::SolverChoice): a trial step per
// candidate, a losing trial stopped as soon as it has lost, the cheapest kept and re-measured on a
// doubling schedule, a regime change followed, and little more cost than the best fixed choice.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "viscompm/newton/solver_choice.hpp"

using viscompm::linalg::SolverChoiceSettings;
using viscompm::newton::SolverChoice;

namespace {
// Runs `steps` steps of `directions` directions each, where a direction of candidate c costs
// cost(c, step); returns the total cost.
double run(SolverChoice& choice, int steps, const std::function<double(int, int)>& cost, int first_step = 0,
           int directions = 4) {
  double total = 0.0;
  for (int step = first_step; step < first_step + steps; ++step) {
    for (int d = 0; d < directions; ++d) {
      const double seconds = cost(choice.next(), step);
      total += seconds;
      choice.direction_solved(seconds);
    }
    choice.step_ended();
  }
  return total;
}
}  // namespace

TEST(SolverChoice, TriesEachCandidateForAStepThenKeepsTheCheapest) {
  SolverChoice choice(2, SolverChoiceSettings{});
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(choice.next(), 0);
    choice.direction_solved(1.0);
  }
  choice.step_ended();  // candidate 0: 3 s for its step
  EXPECT_EQ(choice.next(), 1);
  choice.direction_solved(2.0);
  choice.step_ended();  // candidate 1: 2 s
  EXPECT_EQ(choice.chosen(), 1);
  EXPECT_EQ(choice.trials(), 1);
  EXPECT_EQ(choice.stopped_early(), 0);
  // Until the first recheck (16 steps), the cheaper one solves every direction.
  for (int k = 0; k < 16; ++k) {
    EXPECT_EQ(choice.next(), 1);
    choice.direction_solved(2.0);
    choice.step_ended();
  }
  EXPECT_EQ(choice.next(), 0) << "the other candidate is measured again";
  EXPECT_EQ(choice.systems(), (std::vector<int>{3, 17}));
}

TEST(SolverChoice, ATrialStepThatHasLostIsFinishedByTheBest) {
  // The paper's solver on a stiff scene: candidate 1's directions cost 10× candidate 0's. Its
  // trial step is stopped as soon as it costs more than candidate 0's whole step, and candidate 0
  // computes the rest of that step.
  SolverChoice choice(2, SolverChoiceSettings{});
  run(choice, 1, [](int c, int) { return c == 0 ? 1.0 : 10.0; });  // candidate 0: 4 s
  EXPECT_EQ(choice.next(), 1);
  choice.direction_solved(10.0);  // 10 s > 4 s: lost
  EXPECT_EQ(choice.stopped_early(), 1);
  EXPECT_EQ(choice.next(), 0) << "the best one finishes the step";
  choice.direction_solved(1.0);
  choice.step_ended();
  EXPECT_EQ(choice.chosen(), 0);
  EXPECT_EQ(choice.next(), 0);
}

TEST(SolverChoice, ConfirmedChoicesAreRecheckedOnADoublingSchedule) {
  SolverChoice choice(2, SolverChoiceSettings{});
  std::vector<int> trial_steps;  // the steps at which the dearer candidate ran
  for (int step = 0; step < 2000; ++step) {
    if (choice.next() == 1) trial_steps.push_back(step);
    choice.direction_solved(choice.next() == 1 ? 1.04 : 1.0);
    choice.step_ended();
  }
  // Step 1 (the first trial), then after 16, 32, 64, 128, 256, 256, ... steps of the chosen one
  // (a loser 4 % dearer can be tried that often within a 5 % trial overhead).
  ASSERT_GE(trial_steps.size(), 7u);
  std::vector<int> gaps;
  for (std::size_t k = 1; k < trial_steps.size(); ++k) gaps.push_back(trial_steps[k] - trial_steps[k - 1] - 1);
  const std::vector<int> schedule{16, 32, 64, 128, 256, 256};
  for (std::size_t k = 0; k < schedule.size(); ++k) EXPECT_EQ(gaps[k], schedule[k]) << "gap " << k;
}

TEST(SolverChoice, ALoserThatLostByMuchIsTriedOnlyAsOftenAsTheOverheadAllows) {
  // The multigrid on a soft scene: its trial step costs 5 times the paper's solver's. With a 5 %
  // trial overhead the next trial waits (5 − 1)/0.05 = 80 steps (after the paper's own trial step),
  // then the schedule's 160, 256.
  SolverChoice choice(2, SolverChoiceSettings{});
  std::vector<int> trial_steps;
  for (int step = 0; step < 1000; ++step) {
    if (choice.next() == 0) trial_steps.push_back(step);
    choice.direction_solved(choice.next() == 0 ? 5.0 : 1.0);
    choice.step_ended();
  }
  ASSERT_GE(trial_steps.size(), 5u);
  const std::vector<int> schedule{1 + 80, 160, 256, 256};
  for (std::size_t k = 0; k < schedule.size(); ++k)
    EXPECT_EQ(trial_steps[k + 1] - trial_steps[k] - 1, schedule[k]) << "gap " << k;
}

TEST(SolverChoice, CostsLittleMoreThanTheBestFixedChoice) {
  // Over 1000 steps, candidates 3× apart, in either order: within 3 % of the cheaper one alone
  // (a losing trial step is stopped once it costs more than the winner's step).
  for (const double first : {1.0, 3.0}) {
    SolverChoice choice(2, SolverChoiceSettings{});
    const double total = run(choice, 1000, [first](int c, int) { return c == 0 ? first : 4.0 - first; });
    EXPECT_LE(total, 1.03 * 4000.0) << "first candidate costs " << first;
    EXPECT_GT(total, 4000.0);
  }
  // The Weissenberg sweep: 264 small steps, the multigrid's trial step 10× the paper's: the
  // trials after the first cost at most the overhead.
  {
    SolverChoice choice(2, SolverChoiceSettings{});
    const double total = run(choice, 264, [](int c, int) { return c == 0 ? 10.0 : 1.0; });
    EXPECT_LE(total, 4.0 * 264 * 1.05 + 4.0 * 9.0) << "the first trial's excess, then at most 5 %";
  }
  // And the first of two steps already pays for the trial: 100× apart, two steps cost less than
  // three of the best (the stiff scene at frame steps, the paper's solver tried second).
  SolverChoice choice(2, SolverChoiceSettings{});
  EXPECT_LT(run(choice, 2, [](int c, int) { return c == 0 ? 1.0 : 100.0; }), 3 * 4.0 + 100.0);
}

TEST(SolverChoice, FollowsARegimeChange) {
  // The pie: a soft flight where candidate 1 (the paper's solver) is 3× cheaper, then an impact
  // from step 100 on where it becomes 10× dearer than candidate 0 (the multigrid).
  auto cost = [](int c, int step) {
    if (step < 100) return c == 1 ? 1.0 : 3.0;
    return c == 1 ? 20.0 : 2.0;
  };
  SolverChoice choice(2, SolverChoiceSettings{});
  const double flight = run(choice, 100, cost);
  EXPECT_EQ(choice.chosen(), 1);
  const double impact = run(choice, 200, cost, 100);
  EXPECT_EQ(choice.chosen(), 0);
  EXPECT_EQ(choice.switches(), 1);
  // The change is noticed within Regime steps and a trial, not at the next scheduled recheck.
  const double best = 4 * (100.0 * 1.0 + 200.0 * 2.0);
  EXPECT_LE(flight + impact, 1.05 * best + 4 * 4 * 20.0);
  // Both fixed choices cost more.
  EXPECT_LT(flight + impact, 4 * (100.0 * 3.0 + 200.0 * 2.0));
  EXPECT_LT(flight + impact, 4 * (100.0 * 1.0 + 200.0 * 20.0));
}

TEST(SolverChoice, NoiseBelowTheRegimeFactorTriggersNoTrial) {
  // The chosen one's steps vary by ±40 % (Newton iterations per step vary): with Regime change 2
  // that is no regime change, so trials come only on schedule.
  SolverChoice choice(2, SolverChoiceSettings{});
  run(choice, 1000, [](int c, int step) { return c == 0 ? 1.0 + 0.4 * ((step % 3) - 1) : 4.0; });
  EXPECT_EQ(choice.chosen(), 0);
  EXPECT_LE(choice.trials(), 1 + 6);  // the first, then after 16, 32, 64, 128, 256, 256 steps
  EXPECT_EQ(choice.switches(), 0);
}

TEST(SolverChoice, AStepWithoutDirectionsMeasuresNothing) {
  // A step converged at its initial guess (a body at rest) is no trial: it would make its
  // candidate look free.
  SolverChoice choice(2, SolverChoiceSettings{});
  choice.step_ended();
  EXPECT_EQ(choice.next(), 0);
  EXPECT_EQ(choice.trials(), 0);
  run(choice, 2, [](int c, int) { return c == 0 ? 2.0 : 1.0; });
  EXPECT_EQ(choice.chosen(), 1);
}

TEST(SolverChoice, ThreeCandidates) {
  SolverChoice choice(3, SolverChoiceSettings{});
  std::vector<int> order;
  for (int k = 0; k < 3; ++k) {
    order.push_back(choice.next());
    choice.direction_solved(choice.next() == 2 ? 1.0 : 2.0);
    choice.step_ended();
  }
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(choice.chosen(), 2);
  EXPECT_EQ(choice.systems(), (std::vector<int>{1, 1, 1}));
}

TEST(SolverChoice, OneStepDearerThanTheLoserStartsATrialAtOnce) {
  // The pie at Table 5.1's cell: the paper's solver (candidate 1) wins the first trial on the
  // cream's easy steps (33 s against the multigrid's 45 s, its hierarchy built anew), then the
  // crust reaches the head from step 3 on and a step of it costs 140 s (600 CG iterations), the
  // multigrid's 44 s. The step that jumps past the loser's trial cost starts the next trial.
  auto cost = [](int c, int step) {
    if (c == 0) return step == 0 ? 45.0 / 4 : 44.0 / 4;
    return step < 3 ? 33.0 / 4 : 140.0 / 4;
  };
  SolverChoice choice(2, SolverChoiceSettings{});
  run(choice, 3, cost);
  EXPECT_EQ(choice.chosen(), 1);
  run(choice, 1, cost, 3);  // the first dear step
  EXPECT_EQ(choice.next(), 0) << "the multigrid is tried on the next step";
  run(choice, 10, cost, 4);
  EXPECT_EQ(choice.chosen(), 0);
  EXPECT_EQ(choice.switches(), 1);
}

TEST(SolverChoice, OneStepDearerThanItsReferenceOnlyDoesNotStartATrial) {
  // The same pie, the multigrid chosen (45 s against the paper's 48 s in the first trial); its
  // third step builds its hierarchy anew on a new pattern and costs 94 s: twice its reference but
  // less than twice the loser's, so no trial (the paper's solver then paid a 610-iteration solve).
  auto cost = [](int c, int step) {
    if (c == 1) return step < 20 ? 48.0 / 4 : 140.0 / 4;
    return step == 2 ? 94.0 / 4 : 45.0 / 4;
  };
  SolverChoice choice(2, SolverChoiceSettings{});
  run(choice, 2, cost);
  EXPECT_EQ(choice.chosen(), 0);
  run(choice, 1, cost, 2);  // the dear step
  EXPECT_EQ(choice.next(), 0) << "no trial of the paper's solver";
  EXPECT_EQ(choice.trials(), 1);
}

namespace {
// One step of `directions` directions of candidate next(), costing `step_seconds` in all, the first
// direction carrying `fresh` seconds of a preconditioner built anew.
void step(SolverChoice& choice, double step_seconds, double fresh = 0.0, int directions = 3) {
  for (int d = 0; d < directions; ++d)
    choice.direction_solved(step_seconds / directions + (d == 0 ? fresh : 0.0), d == 0 ? fresh : 0.0);
  choice.step_ended();
}
}  // namespace

TEST(SolverChoice, ACandidateThatLostOnlyByAFreshSetUpSolvesOneMoreTrialStep) {
  // The pie at Table 5.1's cell: the multigrid's first step costs 75 s, 44.5 s of it its first
  // hierarchy; the paper's solver's 48 s. Without the fresh build the multigrid's step was 30.5 s,
  // so it solves the next step too, with its hierarchy reused (38 s), and that step decides.
  SolverChoice choice(2, SolverChoiceSettings{});
  EXPECT_EQ(choice.next(), 0);
  step(choice, 30.5, 44.5);
  EXPECT_EQ(choice.next(), 1);
  step(choice, 48.0);
  EXPECT_EQ(choice.next(), 0) << "a second trial step for the multigrid";
  EXPECT_EQ(choice.warm_ups(), 1);
  EXPECT_EQ(choice.trials(), 0) << "the trial is not over yet";
  step(choice, 38.0);
  EXPECT_EQ(choice.trials(), 1);
  EXPECT_EQ(choice.chosen(), 0);
  EXPECT_EQ(choice.next(), 0);
}

TEST(SolverChoice, TheSecondTrialStepStandsEvenWhenItLosesAgain) {
  // The same, but the multigrid's second step (reused hierarchy) costs 55 s > 48 s: it is stopped
  // as soon as it has lost, and the paper's solver is chosen; no third step.
  SolverChoice choice(2, SolverChoiceSettings{});
  step(choice, 30.5, 44.5);
  step(choice, 48.0);
  EXPECT_EQ(choice.next(), 0);
  choice.direction_solved(25.0);
  choice.direction_solved(25.0);  // 50 s > 48 s: lost
  EXPECT_EQ(choice.stopped_early(), 1);
  EXPECT_EQ(choice.next(), 1) << "the paper's solver finishes the step";
  choice.direction_solved(5.0);
  choice.step_ended();
  EXPECT_EQ(choice.trials(), 1);
  EXPECT_EQ(choice.chosen(), 1);
  EXPECT_EQ(choice.warm_ups(), 1);
}

TEST(SolverChoice, AFreshSetUpThatDidNotDecideTheTrialEarnsNoSecondStep) {
  // 75 s with 10 s of fresh set-up against 48 s: it lost by more than its fresh build.
  SolverChoice choice(2, SolverChoiceSettings{});
  step(choice, 65.0, 10.0);
  step(choice, 48.0);
  EXPECT_EQ(choice.trials(), 1);
  EXPECT_EQ(choice.chosen(), 1);
  EXPECT_EQ(choice.warm_ups(), 0);
  // A trial candidate stopped early by its fresh build is given its second step too: the paper's
  // solver first (48 s), then the multigrid's first direction alone costs 60 s, 50 of them fresh.
  SolverChoice stopped(2, SolverChoiceSettings{});
  stopped.direction_solved(48.0);
  stopped.step_ended();  // candidate 0 (here the paper's solver): 48 s
  EXPECT_EQ(stopped.next(), 1);
  stopped.direction_solved(60.0, 50.0);  // lost, but only by its fresh build
  EXPECT_EQ(stopped.stopped_early(), 1);
  EXPECT_EQ(stopped.next(), 0);
  stopped.direction_solved(1.0);
  stopped.step_ended();
  EXPECT_EQ(stopped.next(), 1) << "the multigrid's second trial step";
  step(stopped, 30.0);
  EXPECT_EQ(stopped.chosen(), 1);
  EXPECT_EQ(stopped.warm_ups(), 1);
}

TEST(SolverChoice, ATrialDirectionHasTheBudgetLeftBeforeItsCandidateLoses) {
  // The multigrid chosen at 35 s per step; the paper's solver on trial spends 17 s on its first
  // direction: its second may take 18 s more before it has lost. Given up there, it has lost and
  // the multigrid computes that direction again; outside the trial there is no budget.
  SolverChoice choice(2, SolverChoiceSettings{});
  EXPECT_TRUE(std::isinf(choice.direction_budget(0.0))) << "nothing measured yet";
  step(choice, 35.0);
  EXPECT_EQ(choice.next(), 1);
  EXPECT_DOUBLE_EQ(choice.direction_budget(5.0), 30.0);
  choice.direction_solved(17.0);
  EXPECT_DOUBLE_EQ(choice.direction_budget(0.0), 18.0);
  EXPECT_DOUBLE_EQ(choice.direction_budget(4.0, 10.0), 24.0) << "a fresh set-up is not held against it yet";
  choice.direction_abandoned(16.0);  // 33 s: stopped before it passed 35 s, lost all the same
  EXPECT_EQ(choice.abandoned(), 1);
  EXPECT_EQ(choice.stopped_early(), 1);
  EXPECT_EQ(choice.next(), 0);
  EXPECT_TRUE(std::isinf(choice.direction_budget(0.0))) << "the best one has no budget";
  choice.direction_solved(10.0);
  choice.step_ended();
  EXPECT_EQ(choice.chosen(), 0);
  EXPECT_EQ(choice.warm_ups(), 0) << "a direction given up at its budget earns no second step";
  EXPECT_EQ(choice.systems(), (std::vector<int>{4, 2}));
}

TEST(SolverChoice, AChosenDirectionOutOfItsRegimeIsGivenUpAndTheLoserTried) {
  // The paper's solver chosen (20 s per step against the multigrid's 25 s); at the impact one of
  // its solves would take 110 s. A direction's budget is the step cost that starts a trial at
  // once, 2 × 25 s, whatever the step's earlier directions cost: given up there, the multigrid
  // computes the rest of the step and is tried on the next.
  SolverChoice choice(2, SolverChoiceSettings{});
  step(choice, 25.0);  // the multigrid (candidate 0)
  step(choice, 20.0);  // the paper's solver
  ASSERT_EQ(choice.chosen(), 1);
  EXPECT_EQ(choice.next(), 1);
  choice.direction_solved(12.0);
  EXPECT_DOUBLE_EQ(choice.direction_budget(3.0), 50.0 - 3.0);
  for (int d = 0; d < 5; ++d) choice.direction_solved(12.0);  // a step of many cheap directions: 72 s
  EXPECT_EQ(choice.next(), 1);
  EXPECT_DOUBLE_EQ(choice.direction_budget(3.0), 50.0 - 3.0);
  choice.direction_abandoned(50.0);  // one direction spent its budget
  EXPECT_EQ(choice.abandoned(), 1);
  EXPECT_EQ(choice.next(), 0) << "the closest loser computes the direction again";
  EXPECT_TRUE(std::isinf(choice.direction_budget(0.0)));
  choice.direction_solved(5.0);
  choice.step_ended();
  EXPECT_EQ(choice.next(), 0) << "and is tried on the next step";
  step(choice, 25.0);
  // 25 s beats the paper solver's recent cost (which holds the dear step): the paper's solver
  // solves a step again, under the multigrid's 25 s, and loses it at the impact.
  EXPECT_EQ(choice.next(), 1) << "the chosen one confirms its regime change";
  EXPECT_DOUBLE_EQ(choice.direction_budget(0.0), 25.0);
  choice.direction_abandoned(25.0);
  EXPECT_EQ(choice.next(), 0) << "the multigrid finishes the step";
  choice.direction_solved(8.0);
  choice.step_ended();
  EXPECT_EQ(choice.chosen(), 0);
  EXPECT_EQ(choice.switches(), 1);
  EXPECT_EQ(choice.confirmations(), 1);
}

TEST(SolverChoice, AStepOfMoreNewtonDirectionsAtTheSameCostPerDirectionStartsNoTrial) {
  // The pie at Δx 0.01: the multigrid's trial step is 3 directions in 0.54 s; the paper's solver
  // is stopped after 2 directions in 0.6 s. When the crust meets the head a step needs 9 Newton
  // directions at 0.15 s each, 1.35 s: dearer than twice both step costs, but no dearer per
  // direction, so the paper's solver (which needs those 9 directions too) is not tried.
  SolverChoice choice(2, SolverChoiceSettings{});
  step(choice, 0.54);
  choice.direction_solved(0.05);
  choice.direction_solved(0.55);
  ASSERT_EQ(choice.stopped_early(), 1);
  choice.direction_solved(0.1);
  choice.step_ended();
  ASSERT_EQ(choice.chosen(), 0);
  for (int k = 0; k < 3; ++k) step(choice, 1.35, 0.0, 9);  // 0.15 s per direction
  EXPECT_EQ(choice.next(), 0) << "no trial";
  EXPECT_EQ(choice.trials(), 1);
  // Dearer per direction than twice both trials' (0.18 s and 0.3 s) does start one: 0.7 s.
  step(choice, 2.1, 0.0, 3);
  EXPECT_EQ(choice.next(), 1);
}

namespace {
// The multigrid (candidate 0) at 10 s per step of 4 directions but 305 s at step 20 (the process
// held stopped); the paper's solver (candidate 1) at `loser_step_seconds` per step.
std::function<double(int, int)> outlier_costs(double loser_step_seconds) {
  return [loser_step_seconds](int c, int step) {
    if (c == 1) return loser_step_seconds / 4;
    return step == 20 ? 305.0 / 4 : 10.0 / 4;
  };
}
}  // namespace

TEST(SolverChoice, OneOutlierStepOfTheChosenOneDoesNotHandTheLoserTheChoice) {
  // The pie at Δx 0.005 on one rank, the process held stopped during one step: the multigrid
  // (chosen, 10 s per step) "costs" 305 s once; the paper's solver's trial step takes 35 s, less
  // than the multigrid's running mean (which holds the 305 s). The multigrid solves a step again
  // under the 35 s, in its usual 10 s, and stays chosen: not 28 steps of the paper's solver at
  // 3.5× the cost, as with the running mean standing for it.
  const auto cost = outlier_costs(35.0);
  SolverChoice choice(2, SolverChoiceSettings{});
  run(choice, 20, cost);
  ASSERT_EQ(choice.chosen(), 0);
  const int paper_before = choice.systems()[1];
  run(choice, 1, cost, 20);  // the outlier
  EXPECT_EQ(choice.next(), 1) << "a trial of the paper's solver";
  run(choice, 1, cost, 21);
  EXPECT_EQ(choice.next(), 0) << "the multigrid confirms";
  EXPECT_DOUBLE_EQ(choice.direction_budget(0.0), 35.0);
  const double after = run(choice, 30, cost, 22);
  EXPECT_EQ(choice.chosen(), 0);
  EXPECT_EQ(choice.switches(), 0);
  EXPECT_EQ(choice.confirmations(), 1);
  EXPECT_EQ(choice.systems()[1] - paper_before, 4) << "the one trial step only";
  EXPECT_DOUBLE_EQ(after, 30 * 10.0);
}

TEST(SolverChoice, ALoserDearerThanTheOutlierNeedsNoConfirmingStep) {
  // The same outlier against a loser dearer than even the running mean that holds it (the paper's
  // solver 12× the multigrid: 120 s per step, 83.75 s the mean): the trial stops the loser at
  // that mean, and the multigrid goes on without a confirming step.
  const auto cost = outlier_costs(120.0);
  SolverChoice choice(2, SolverChoiceSettings{});
  run(choice, 21, cost);
  EXPECT_EQ(choice.next(), 1);
  EXPECT_DOUBLE_EQ(choice.direction_budget(0.0), 0.75 * 10.0 + 0.25 * 305.0);
  run(choice, 1, cost, 21);
  EXPECT_EQ(choice.stopped_early(), 2) << "the first trial's and this one's";
  EXPECT_EQ(choice.next(), 0);
  EXPECT_EQ(choice.chosen(), 0);
  EXPECT_EQ(choice.confirmations(), 0);
}
