// The measured choice between solver configurations (a solver file's `Choose between`): which
// candidate computes the next Newton direction, from the wall seconds the directions took. Plain
// logic (no Trilinos, no clock), so that it can be tested on its own; NewtonSolver asks it before
// each direction and tells it what the direction cost (its seconds per decade of residual
// reduction: the unit below is one Newton direction, a "step" of the schedule).
//
// Trial: every candidate computes `Trial systems` directions in turn; the cheapest per direction is
// chosen. Then the chosen one computes them, and the others are tried again (one trial each)
// after `Recheck systems` directions, an interval that doubles (to `Max recheck systems`) each time
// the trial confirms the choice, or at once when the chosen one's cost moves by more than the
// factor `Regime change` from what it cost when it was last confirmed (the scene changed regime:
// a soft body met a stiff one). A trial that finds a cheaper candidate switches to it.
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
  /// The direction computed by next() cost `seconds` (normalised by the caller; failed attempts
  /// included). The same value on every rank (the caller agrees it).
  void solved(double seconds);
  /// The chosen candidate (the cheapest of the last trial; during the first trial, the first).
  int chosen() const { return chosen_; }
  /// Directions computed by each candidate so far.
  const std::vector<int>& systems() const { return systems_; }
  /// Trials run so far (the first one included) and choices changed by them.
  int trials() const { return trials_; }
  int switches() const { return switches_; }

 private:
  void start_trial();
  void end_trial();

  linalg::SolverChoiceSettings settings_;
  int candidates_;
  int next_ = 0;
  int chosen_ = 0;
  bool in_trial_ = true;
  std::vector<double> trial_seconds_;  ///< per candidate, summed over the current trial
  std::vector<int> trial_systems_;       ///< per candidate, directions of the current trial
  std::vector<int> systems_;          ///< directions computed by each candidate
  double reference_ = 0.0;             ///< the chosen one's seconds per step when last confirmed
  double recent_ = 0.0;                ///< its recent cost per direction (a running mean)
  int since_trial_ = 0;                ///< directions of the chosen one since the last trial
  int interval_ = 0;                   ///< directions until the next trial
  int trials_ = 0;
  int switches_ = 0;
};

}  // namespace viscompm::newton
