#include "viscompm/newton/solver_choice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace viscompm::newton {

namespace {
// Weight of the newest step in the chosen candidate's recent cost per step.
constexpr double recent_weight = 0.25;
}  // namespace

SolverChoice::SolverChoice(int candidates, const linalg::SolverChoiceSettings& settings)
    : settings_(settings),
      candidates_(candidates),
      trial_cost_(static_cast<std::size_t>(candidates), -1.0),
      trial_fresh_(static_cast<std::size_t>(candidates), 0.0),
      trial_per_direction_(static_cast<std::size_t>(candidates), 0.0),
      warmed_up_(static_cast<std::size_t>(candidates), false),
      systems_(static_cast<std::size_t>(candidates), 0),
      interval_(settings.recheck_steps) {
  if (candidates < 1) throw std::invalid_argument("SolverChoice: no candidate");
  in_trial_ = candidates > 1;
}

int SolverChoice::cheapest() const {
  int best = -1;
  for (int c = 0; c < candidates_; ++c)
    if (trial_cost_[c] >= 0.0 && (best < 0 || trial_cost_[c] < trial_cost_[best])) best = c;
  return best;
}

void SolverChoice::direction_solved(double seconds, double fresh_setup_seconds) {
  ++systems_[next_];
  ++step_directions_;
  step_cost_ += seconds;
  if (next_ == on_trial_) step_fresh_ += fresh_setup_seconds;
  // A candidate on trial that already cost more than the best step of this trial has lost: the
  // best one finishes the step.
  if (!trial_step_running()) return;
  const int best = cheapest();
  if (best >= 0 && step_cost_ > trial_cost_[best]) lose_trial(best, step_cost_);
}

void SolverChoice::record_trial_step(double cost) {
  trial_cost_[on_trial_] = cost;
  trial_fresh_[on_trial_] = step_fresh_;
  trial_per_direction_[on_trial_] = cost / step_directions_;
}

void SolverChoice::lose_trial(int best, double cost) {
  lost_ = true;
  ++stopped_early_;
  record_trial_step(cost);
  next_ = best;
}

double SolverChoice::direction_budget(double spent_seconds, double fresh_setup_seconds) const {
  constexpr double unlimited = std::numeric_limits<double>::infinity();
  if (!in_trial_) {
    // The chosen one: until this one direction costs what would start a trial at once if it were
    // a whole step (step_ended). Not the step's sum: a step of many cheap directions is no sign
    // that the loser (its trial cost often a lower bound) would do it cheaper.
    if (next_ != chosen_ || !std::isfinite(loser_cost_)) return unlimited;
    return settings_.regime_change * std::max(reference_, loser_cost_) - spent_seconds;
  }
  // On trial: until it costs more than the best step of the trial so far.
  const int best = cheapest();
  if (!trial_step_running() || best < 0) return unlimited;
  const double held = warmed_up_[on_trial_] ? 0.0 : step_fresh_ + fresh_setup_seconds;
  return trial_cost_[best] - (step_cost_ + spent_seconds - held);
}

void SolverChoice::direction_abandoned(double seconds, double fresh_setup_seconds) {
  ++abandoned_;
  if (!in_trial_ && next_ == chosen_) {
    // The chosen one jumped out of its regime within a step: the closest loser finishes the step,
    // and a trial starts with the next one.
    direction_solved(seconds, fresh_setup_seconds);
    jumped_within_step_ = true;
    next_ = closest_loser_;
    return;
  }
  const bool on_trial = trial_step_running();
  direction_solved(seconds, fresh_setup_seconds);
  if (!on_trial || lost_) return;
  // Stopped a little before its cost passed the best's: it has lost all the same (and not by a
  // fresh set-up, which its budget did not count).
  const int best = cheapest();
  warmed_up_[on_trial_] = true;
  lose_trial(best, std::max(step_cost_, std::nextafter(trial_cost_[best], std::numeric_limits<double>::infinity())));
}

void SolverChoice::step_ended() {
  // A step whose initial guess already converged measured nothing.
  if (step_directions_ == 0) return;
  if (in_trial_ && !lost_) record_trial_step(step_cost_);
  const double cost = step_cost_;
  const int directions = step_directions_;
  step_cost_ = 0.0;
  step_fresh_ = 0.0;
  step_directions_ = 0;
  if (in_trial_) {
    lost_ = false;
    next_trial_candidate();
    return;
  }
  // The chosen one: its recent cost per step and per direction, and a trial when it is due or
  // the cost per direction left its regime.
  const double per_direction = cost / directions;
  const auto mean = [this](double previous, double newest) {
    return since_trial_ == 0 ? newest : (1.0 - recent_weight) * previous + recent_weight * newest;
  };
  recent_ = mean(recent_, cost);
  recent_per_direction_ = mean(recent_per_direction_, per_direction);
  ++since_trial_;
  // A change smaller than the margin the loser lost by cannot reverse the choice.
  const double factor = std::max(settings_.regime_change, margin_);
  const bool regime_changed =
      since_trial_ >= settings_.regime_steps && (recent_per_direction_ > factor * reference_per_direction_ ||
                                                 recent_per_direction_ * factor < reference_per_direction_);
  // One step whose directions cost the regime factor times both the reference's and the closest
  // loser's trial directions cannot wait for the running mean: the loser may already be the
  // cheaper (the pie's crust reaching the head while the paper's solver is chosen). A step only
  // dearer than its reference (a hierarchy built anew) is left to the mean.
  const bool jumped = jumped_within_step_ || per_direction > settings_.regime_change *
                                                                 std::max(reference_per_direction_, loser_per_direction_);
  jumped_within_step_ = false;
  next_ = chosen_;
  if (regime_changed || jumped) interval_ = settings_.recheck_steps;
  if (regime_changed || jumped || since_trial_ >= interval_) start_trial(regime_changed || jumped);
}

void SolverChoice::start_trial(bool confirm_chosen) {
  if (candidates_ == 1) return;
  in_trial_ = true;
  confirm_chosen_ = confirm_chosen;
  std::fill(trial_cost_.begin(), trial_cost_.end(), -1.0);
  std::fill(trial_fresh_.begin(), trial_fresh_.end(), 0.0);
  std::fill(warmed_up_.begin(), warmed_up_.end(), false);
  // The chosen one is not run again: its recent cost stands for it (after a regime change, until a
  // loser beats it: then the chosen one solves a step of its own, next_trial_candidate).
  trial_cost_[chosen_] = recent_;
  trial_per_direction_[chosen_] = recent_per_direction_;
  next_trial_candidate();
}

void SolverChoice::next_trial_candidate() {
  for (int c = 0; c < candidates_; ++c)
    if (trial_cost_[c] < 0.0) {
      on_trial_ = next_ = c;
      return;
    }
  // Every candidate measured. After a regime change the chosen one's recent cost may hold one
  // outlier step (a process held stopped, a crowded machine): a loser that beat it does not win on
  // that, the chosen one solves a step under the trial's budget and its cost stands instead. In a
  // true regime change that costs at most about one step of the loser.
  const int leader = cheapest();
  if (confirm_chosen_ && leader != chosen_) {
    confirm_chosen_ = false;
    ++confirmations_;
    trial_cost_[chosen_] = -1.0;
    on_trial_ = next_ = chosen_;
    return;
  }
  confirm_chosen_ = false;
  // One that lost only by a preconditioner built anew on a new pattern
  // (its first hierarchy of the run, or the first since the pattern changed while another solved)
  // measured a one-off: it solves one more step, whose cost stands instead.
  for (int c = 0; c < candidates_; ++c)
    if (c != leader && !warmed_up_[c] && trial_fresh_[c] > 0.0 && trial_cost_[c] - trial_fresh_[c] < trial_cost_[leader]) {
      warmed_up_[c] = true;
      ++warm_ups_;
      trial_cost_[c] = -1.0;
      trial_fresh_[c] = 0.0;
      on_trial_ = next_ = c;
      return;
    }
  const int best = leader;
  const bool confirmed = trials_ > 0 && best == chosen_;
  if (trials_ > 0 && best != chosen_) ++switches_;
  ++trials_;
  // The margin: how many times the winner's cost the closest loser's step cost (at least; a
  // stopped one's is a lower bound).
  loser_cost_ = std::numeric_limits<double>::infinity();
  for (int c = 0; c < candidates_; ++c)
    if (c != best && trial_cost_[c] < loser_cost_) {
      loser_cost_ = trial_cost_[c];
      closest_loser_ = c;
    }
  margin_ = trial_cost_[best] > 0.0 && std::isfinite(loser_cost_) ? std::max(loser_cost_ / trial_cost_[best], 1.0) : 1.0;
  loser_per_direction_ = std::isfinite(loser_cost_) ? trial_per_direction_[closest_loser_] : 0.0;
  // A confirmed choice is checked half as often from now on; a new one as often as at first; and
  // never so often that the losers' trial steps cost more than `Trial overhead` of the winner's.
  interval_ = confirmed ? std::min(2 * interval_, settings_.max_recheck_steps) : settings_.recheck_steps;
  const double affordable = std::ceil((margin_ - 1.0) / settings_.trial_overhead);
  interval_ = std::max(interval_, static_cast<int>(std::min<double>(affordable, settings_.max_recheck_steps)));
  chosen_ = next_ = best;
  reference_ = recent_ = trial_cost_[best];
  reference_per_direction_ = recent_per_direction_ = trial_per_direction_[best];
  since_trial_ = 0;
  in_trial_ = false;
}

}  // namespace viscompm::newton
