// The reuse rules of Newton's strategies on their own: when H is assembled again and when its
// preconditioner is set up again, for every Hessian update and Preconditioner update, the refresh
// rule (line search, contraction, CG growth), and what a new Δt, a new pattern, a failure or the
// matrix-free operator do to what was kept.
#include <gtest/gtest.h>

#include "viscompm/newton/reuse_rules.hpp"

using namespace viscompm::newton;

namespace {
NewtonSettings strategy(HessianUpdate hessian, PreconditionerUpdate preconditioner) {
  NewtonSettings s;
  s.hessian_update = hessian;
  s.preconditioner_update = preconditioner;
  return s;
}

// One iteration as NewtonSolver drives it when nothing fails: assemble if asked, set up if asked,
// solve in `cg` iterations, accept the full step. Returns {assembled, set up}.
std::pair<bool, bool> iterate(ReuseRules& rules, int cg = 10, double alpha = 1.0) {
  const bool assemble = rules.assemble_now();
  if (assemble) rules.assembled(false);
  const bool setup = rules.setup_now();
  if (setup) rules.preconditioned();
  rules.solved(cg, 1e-6);
  rules.line_search_step(alpha);
  return {assemble, setup};
}
}  // namespace

TEST(ReuseRules, ExactNewtonAssemblesAndSetsUpAtEveryIteration) {
  ReuseRules rules(strategy(HessianUpdate::every_iteration, PreconditionerUpdate::every_assembly));
  rules.begin_solve(0.01, 1, false);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(iterate(rules), std::make_pair(true, true)) << k;
}

TEST(ReuseRules, HessianOncePerStepIsKeptUntilTheRefreshRuleFires) {
  ReuseRules rules(strategy(HessianUpdate::every_step, PreconditionerUpdate::every_assembly));
  rules.begin_solve(0.01, 1, false);
  EXPECT_EQ(iterate(rules), std::make_pair(true, true));
  EXPECT_EQ(iterate(rules), std::make_pair(false, false));
  // A shortened step refreshes H (and, every assembly, the preconditioner with it).
  EXPECT_EQ(iterate(rules, 10, 0.5), std::make_pair(false, false));
  EXPECT_EQ(iterate(rules), std::make_pair(true, true));
  // A residual that shrinks by less than the contraction factor refreshes H.
  rules.residual(1.0, 0.9);
  EXPECT_TRUE(rules.assemble_now());
  iterate(rules);
  // CG needing more than Refresh growth times its first count refreshes H.
  EXPECT_EQ(iterate(rules, 16), std::make_pair(false, false));
  EXPECT_TRUE(rules.assemble_now());
  // A new step assembles again.
  iterate(rules);
  rules.begin_solve(0.01, 1, false);
  EXPECT_TRUE(rules.assemble_now());
}

TEST(ReuseRules, ALaggedHessianLivesAcrossStepsOnlyWithTheSameGraphAndTimeStep) {
  ReuseRules rules(strategy(HessianUpdate::lagged, PreconditionerUpdate::lagged));
  rules.begin_solve(0.01, 1, false);
  EXPECT_EQ(iterate(rules), std::make_pair(true, true));
  rules.begin_solve(0.01, 1, false);
  EXPECT_EQ(iterate(rules), std::make_pair(false, false));
  EXPECT_TRUE(rules.preconditioner_matches_hessian());
  rules.begin_solve(0.005, 1, false);  // another Δt: another H = M + Δt² K
  EXPECT_EQ(iterate(rules), std::make_pair(true, true));
  rules.begin_solve(0.005, 2, false);  // another graph
  EXPECT_EQ(iterate(rules), std::make_pair(true, true));
  rules.begin_solve(0.005, 2, true);  // matrix-free pieces belong to their step
  EXPECT_TRUE(rules.assemble_now());
}

TEST(ReuseRules, APreconditionerKeptOncePerStepNoLongerMatchesAReassembledHessian) {
  ReuseRules rules(strategy(HessianUpdate::every_iteration, PreconditionerUpdate::every_step));
  rules.begin_solve(0.01, 1, false);
  EXPECT_EQ(iterate(rules), std::make_pair(true, true));
  EXPECT_TRUE(rules.preconditioner_matches_hessian());
  EXPECT_EQ(iterate(rules), std::make_pair(true, false));
  EXPECT_FALSE(rules.preconditioner_matches_hessian());
  rules.begin_solve(0.01, 1, false);
  EXPECT_EQ(iterate(rules), std::make_pair(true, true));
}

TEST(ReuseRules, ALaggedPreconditionerIsRefreshedWhenCgSlowsDown) {
  ReuseRules rules(strategy(HessianUpdate::every_iteration, PreconditionerUpdate::lagged));
  rules.begin_solve(0.01, 1, false);
  EXPECT_EQ(iterate(rules, 10), std::make_pair(true, true));
  EXPECT_EQ(iterate(rules, 15), std::make_pair(true, false));
  rules.begin_solve(0.01, 1, false);
  EXPECT_EQ(iterate(rules, 16), std::make_pair(true, false));  // 16 > 1.5 × 10: refresh next
  EXPECT_EQ(iterate(rules, 10), std::make_pair(true, true));
}

TEST(ReuseRules, SolvesToDifferentTolerancesAreComparedPerDecadeOfReduction) {
  ReuseRules rules(strategy(HessianUpdate::every_iteration, PreconditionerUpdate::lagged));
  rules.begin_solve(0.01, 1, false);
  rules.assembled(false);
  rules.preconditioned();
  rules.solved(10, 0.1);  // 10 iterations per decade
  rules.assembled(false);
  EXPECT_FALSE(rules.setup_now());
  rules.solved(50, 1e-6);  // 8.3 per decade: as fast
  rules.assembled(false);
  EXPECT_FALSE(rules.setup_now());
  rules.solved(40, 1e-2);  // 20 per decade: slower than 1.5 × 10
  rules.assembled(false);
  EXPECT_TRUE(rules.setup_now());
}

TEST(ReuseRules, ADemandForFreshMatricesAndForgettingRebuildBoth) {
  ReuseRules rules(strategy(HessianUpdate::lagged, PreconditionerUpdate::lagged));
  rules.begin_solve(0.01, 1, false);
  iterate(rules);
  EXPECT_FALSE(rules.assemble_now());
  rules.demand_fresh();
  EXPECT_EQ(iterate(rules), std::make_pair(true, true));
  rules.forget();
  rules.begin_solve(0.01, 1, false);
  EXPECT_EQ(iterate(rules), std::make_pair(true, true));
}

TEST(ReuseRules, AKeptHessianRemembersWhetherItWasProjected) {
  ReuseRules rules(strategy(HessianUpdate::every_step, PreconditionerUpdate::every_step));
  rules.begin_solve(0.01, 1, false);
  rules.assembled(true);
  EXPECT_TRUE(rules.kept_projected());
  rules.assembled(false);
  EXPECT_FALSE(rules.kept_projected());
}
