#include "viscompm/newton/solver_choice.hpp"

#include <algorithm>
#include <stdexcept>

namespace viscompm::newton {

namespace {
// Weight of the newest step in the chosen candidate's recent cost per step.
constexpr double recent_weight = 0.25;
}  // namespace

SolverChoice::SolverChoice(int candidates, const linalg::SolverChoiceSettings& settings)
    : settings_(settings),
      candidates_(candidates),
      trial_seconds_(static_cast<std::size_t>(candidates), 0.0),
      trial_systems_(static_cast<std::size_t>(candidates), 0),
      systems_(static_cast<std::size_t>(candidates), 0),
      interval_(settings.recheck_systems) {
  if (candidates < 1) throw std::invalid_argument("SolverChoice: no candidate");
}

void SolverChoice::solved(double seconds) {
  ++systems_[next_];
  if (in_trial_) {
    trial_seconds_[next_] += seconds;
    ++trial_systems_[next_];
    // The next candidate still to be tried, in order; the trial ends when none is left.
    for (int c = 0; c < candidates_; ++c)
      if (trial_systems_[c] < settings_.trial_systems) {
        next_ = c;
        return;
      }
    end_trial();
    return;
  }
  // The chosen one: its recent cost, and a trial when it is due or the cost left its regime.
  recent_ = since_trial_ == 0 ? seconds : (1.0 - recent_weight) * recent_ + recent_weight * seconds;
  ++since_trial_;
  const bool regime_changed = since_trial_ >= settings_.regime_systems &&
                              (recent_ > settings_.regime_change * reference_ ||
                               recent_ * settings_.regime_change < reference_);
  if (regime_changed) interval_ = settings_.recheck_systems;
  if (regime_changed || since_trial_ >= interval_) start_trial();
}

void SolverChoice::start_trial() {
  if (candidates_ == 1) {
    since_trial_ = 0;
    reference_ = recent_;
    return;
  }
  in_trial_ = true;
  std::fill(trial_seconds_.begin(), trial_seconds_.end(), 0.0);
  std::fill(trial_systems_.begin(), trial_systems_.end(), 0);
  // The chosen one is not run again: its recent cost stands for it.
  trial_systems_[chosen_] = settings_.trial_systems;
  trial_seconds_[chosen_] = recent_ * settings_.trial_systems;
  for (int c = 0; c < candidates_; ++c)
    if (trial_systems_[c] < settings_.trial_systems) {
      next_ = c;
      break;
    }
}

void SolverChoice::end_trial() {
  int best = 0;
  for (int c = 1; c < candidates_; ++c)
    if (trial_seconds_[c] / trial_systems_[c] < trial_seconds_[best] / trial_systems_[best]) best = c;
  const bool confirmed = trials_ > 0 && best == chosen_;
  if (trials_ > 0 && best != chosen_) ++switches_;
  ++trials_;
  // A confirmed choice is checked half as often from now on; a new one as often as at first.
  interval_ = confirmed ? std::min(2 * interval_, settings_.max_recheck_systems) : settings_.recheck_systems;
  chosen_ = best;
  next_ = best;
  reference_ = recent_ = trial_seconds_[best] / trial_systems_[best];
  since_trial_ = 0;
  in_trial_ = false;
}

}  // namespace viscompm::newton
