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
// at once when the chosen one's cost per direction moves by more than the factor `Regime change`,
// or the margin the loser lost by if larger, from what it cost when last confirmed (a soft body
// met a stiff one), or when a single step's directions cost on average `Regime change` times both
// that and the closest loser's trial directions. In a trial a regime change started, the chosen
// one's recent cost does not decide alone (one outlier step moves it: a process held stopped): if
// a loser beats it, the chosen one solves a step too, under the trial's budget. Per direction,
// not per step: a step that needs more Newton iterations (the crust's impact) needs them
// whichever candidate solves it, so it is no sign that the loser became the cheaper. A trial that finds a cheaper candidate switches to
// it. A candidate that lost its trial step only by a preconditioner built anew (a first hierarchy costs several
// reused set-ups) solves one more step, and that step's cost stands for it. Within a step, a
// direction has a budget (direction_budget): a trial's until its candidate has lost, the chosen
// one's until the direction alone costs what, as a step, would start a trial at once; a Krylov solve that spends it is given up and
// the direction computed by the best candidate (the chosen one's: by the closest loser).
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
  /// agrees it), of which `fresh_setup_seconds` built a preconditioner anew on a new pattern.
  void direction_solved(double seconds, double fresh_setup_seconds = 0.0);
  /// The seconds the direction under way may still take, given what it has spent so far
  /// (`fresh_setup_seconds` of it on a fresh set-up): on trial, before its candidate has lost (a
  /// fresh set-up not held against it before its second trial step); for the chosen one, before
  /// this one direction costs what starts a trial at once as a step's cost (`Regime change` times
  /// both its reference and the closest loser's trial step). Infinite when nothing bounds it (the first trial's first step).
  double direction_budget(double spent_seconds, double fresh_setup_seconds = 0.0) const;
  /// The direction under way was given up (its solve ran out of direction_budget()). On trial: the
  /// candidate has lost, and the best one computes the direction again. The chosen one: the
  /// closest loser computes it and the rest of the step, and a trial starts with the next step.
  void direction_abandoned(double seconds, double fresh_setup_seconds = 0.0);
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
  /// Extra trial steps given to candidates that lost only by a fresh set-up.
  int warm_ups() const { return warm_ups_; }
  /// Directions given up when their solve ran out of direction_budget().
  int abandoned() const { return abandoned_; }
  /// Trials after a regime change in which the chosen one solved a step again, a loser having
  /// beaten its recent cost.
  int confirmations() const { return confirmations_; }

 private:
  /// `confirm_chosen`: a regime change started it, so the chosen one's recent cost stands only
  /// until a loser beats it, and then the chosen one solves a step of its own.
  void start_trial(bool confirm_chosen);
  void next_trial_candidate();
  int cheapest() const;
  /// The candidate on trial is computing this step's directions (it has not lost yet).
  bool trial_step_running() const { return in_trial_ && !lost_ && next_ == on_trial_; }
  /// The candidate on trial's step cost `cost` (its fresh set-up and directions those of the step so far).
  void record_trial_step(double cost);
  /// It has lost at `cost` (a lower bound if stopped early): the best one finishes the step.
  void lose_trial(int best, double cost);

  linalg::SolverChoiceSettings settings_;
  int candidates_;
  int next_ = 0;
  int chosen_ = 0;
  bool in_trial_ = true;
  int on_trial_ = 0;                   ///< the candidate whose trial step this is
  bool lost_ = false;                  ///< it was stopped this step
  std::vector<double> trial_cost_;     ///< per candidate, its step's cost in the current trial (< 0: not yet)
  std::vector<double> trial_fresh_;    ///< per candidate, the fresh set-up seconds in its trial step
  std::vector<double> trial_per_direction_;  ///< per candidate, its trial step's cost per direction (of those done)
  std::vector<bool> warmed_up_;        ///< per candidate, it was given a second trial step this trial
  double step_cost_ = 0.0;             ///< the current step's cost so far
  double step_fresh_ = 0.0;            ///< of it, preconditioners built anew by the candidate on trial
  int step_directions_ = 0;            ///< and its directions
  std::vector<int> systems_;           ///< directions computed by each candidate
  double reference_ = 0.0;             ///< the chosen one's cost per step when last confirmed
  double recent_ = 0.0;                ///< its recent cost per step (a running mean)
  double reference_per_direction_ = 0.0;  ///< the chosen one's cost per direction when last confirmed
  double recent_per_direction_ = 0.0;     ///< its recent cost per direction (a running mean of steps' averages)
  double loser_per_direction_ = 0.0;      ///< the closest loser's trial cost per direction
  double margin_ = 1.0;                ///< the closest loser's cost over the winner's, last trial
  double loser_cost_ = 0.0;            ///< the closest loser's step cost, last trial (a lower bound if stopped)
  int closest_loser_ = 0;              ///< the candidate of loser_cost_
  bool confirm_chosen_ = false;        ///< this trial's chosen one solves a step if a loser beats its recent cost
  bool jumped_within_step_ = false;    ///< the chosen one's direction was given up this step
  int since_trial_ = 0;                ///< steps of the chosen one since the last trial
  int interval_ = 0;                   ///< steps until the next trial
  int trials_ = 0;
  int switches_ = 0;
  int stopped_early_ = 0;
  int warm_ups_ = 0;
  int abandoned_ = 0;
  int confirmations_ = 0;
};

}  // namespace viscompm::newton
