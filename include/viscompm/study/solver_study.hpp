// Preconditioner studies (viscompm-study, doc/contracts.md): the same Newton systems solved with
// several solver configurations. A problem is the first Newton system of a scene's step at a
// given cell size and Δt (after advancing the scene to a chosen time), or a MatrixMarket file.
// Writes DIR/study.csv (one row per problem, resolution and configuration), DIR/operators.csv
// (assembly and operator-application times) and DIR/study.png.
#pragma once

#include <iosfwd>
#include <string>

#include "viscompm/core/parameters.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/scene/scene.hpp"

namespace viscompm::study {

struct StudySettings {
  std::string scene;                  ///< scene XML, relative to the study file
  RealList cell_sizes;                ///< resolutions Δx [m]
  RealList time_steps;                ///< Δt, in `time_step_unit`
  std::string time_step_unit = "elastic CFL";
  double time = 0.0;                  ///< advance the scene to this time first [s]
  std::string right_hand_side = "newton";  ///< newton: −∇E; random: a fixed random load
  StringList solvers;                 ///< solver XML files, relative to the study file
  StringList matrix_market_files;     ///< extra problems, relative to the study file
  int repetitions = 1;                ///< solves per (problem, configuration); the fastest is kept
  std::string output_directory = "output/study";
  bool plot = true;

  static const ParameterTable<StudySettings>& table();
};

/// Reads and validates a study file (InputError with file and parameter on bad input).
StudySettings read_study(const std::string& file, const std::vector<scene::Override>& overrides);

/// Runs the study, logging progress on rank 0. Returns the number of rows written.
int run_study(const StudySettings& settings, const std::string& study_file, const parallel::Communicator& comm,
              std::ostream& log);

}  // namespace viscompm::study
