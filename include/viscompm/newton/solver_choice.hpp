// The measured choice between solver configurations (a solver file's `Choose between`): which
// candidate computes the next Newton direction, from the wall seconds the time steps took. Plain
// logic (no Trilinos, no clock), so that it can be tested on its own; NewtonSolver asks it before
// each direction and tells it what each direction cost and when a step's solve ended.
//
// Trials: each candidate solves one whole time step in turn, in order; the cheapest per step is
// chosen. A candidate on trial whose step has already cost more than the best step of the trial
// so far is stopped at once (it lost; the best one finishes the step), so a trial costs at most
// about one step of the winner more than the winner alone. Then the chosen one solves the steps,
// and the others are tried again (one trial each; the chosen one's recent cost per step stands
// for it) after `Recheck steps` steps, an interval that doubles (to `Max recheck steps`) each
// time a trial confirms the choice and is never shorter than the losers' trial steps can pay for
// (their excess over the winner at most `Trial overhead` of the winner's steps in between); or
// at once when the chosen one's cost per step moves by more than the factor `Regime change`, or
// the margin the loser lost by if larger, from what it cost when last confirmed (a soft body met
// a stiff one), or when a single step of it costs `Regime change` times both that and the
// closest loser's trial step. A trial that finds a cheaper candidate switches to it.
#pragma once

#include <cstddef>
#include <vector>

#include "viscompm/linalg/linear_solver.hpp"

namespace viscompm::newton {

class SolverChoice {
 public:
  SolverChoice(int candidates, const linalg::SolverChoiceSettings& settings);

  /// The candidate that computes the next direction.
  int next() const { return next_; }
  /// The direction computed by next() took `seconds` (the same value on every rank: the caller
  /// agrees it).
  void direction_solved(double seconds);
  /// The step's Newton solve ended (converged or not: a failed step's cost counts too; a step
  /// without a direction, converged at its initial guess, counts for nothing).
  void step_ended();

  /// The chosen candidate (the cheapest of the last trial; during the first trial, the first).
  int chosen() const { return chosen_; }
  /// Directions computed by each candidate so far.
  const std::vector<int>& systems() const { return systems_; }
  /// Trials completed so far (the first one included), choices changed by them, and trial steps
  /// stopped early because the candidate had already lost.
  int trials() const { return trials_; }
  int switches() const { return switches_; }
  int stopped_early() const { return stopped_early_; }

 private:
  void start_trial();
  void next_trial_candidate();
  int cheapest() const;

  linalg::SolverChoiceSettings settings_;
  int candidates_;
  int next_ = 0;
  int chosen_ = 0;
  bool in_trial_ = true;
  int on_trial_ = 0;                   ///< the candidate whose trial step this is
  bool lost_ = false;                  ///< it was stopped this step
  std::vector<double> trial_cost_;     ///< per candidate, its step's cost in the current trial (< 0: not yet)
  double step_cost_ = 0.0;             ///< the current step's cost so far
  int step_directions_ = 0;            ///< and its directions
  std::vector<int> systems_;           ///< directions computed by each candidate
  double reference_ = 0.0;             ///< the chosen one's cost per step when last confirmed
  double recent_ = 0.0;                ///< its recent cost per step (a running mean)
  double margin_ = 1.0;                ///< the closest loser's cost over the winner's, last trial
  double loser_cost_ = 0.0;            ///< the closest loser's step cost, last trial (a lower bound if stopped)
  int since_trial_ = 0;                ///< steps of the chosen one since the last trial
  int interval_ = 0;                   ///< steps until the next trial
  int trials_ = 0;
  int switches_ = 0;
  int stopped_early_ = 0;
};

}  // namespace viscompm::newton
