// Solver studies (viscompm-study), in two modes.
//
// systems: the same Newton systems solved with several solver configurations. A problem is the
//   first Newton system of a scene's step at a given cell size and Δt (after advancing the scene
//   to a chosen time; one scene, or several in a "Scenes" sublist), or a MatrixMarket file.
//   Writes DIR/study.csv (one row per problem, resolution and configuration; time to solution =
//   operator_seconds + setup_seconds + solve_seconds; the cost of one operator and one
//   preconditioner application and the peak memory beside it), DIR/operators.csv (operator
//   preparation and application) and DIR/study.png.
// steps: whole frames of a scene, once per configuration (a solver file and Newton settings),
//   to the same Newton tolerance. Writes DIR/steps.csv (iterations, wall time and where it went)
//   and DIR/steps.png.
// doc/inputs.md lists the parameters; doc/contracts.md the CSV columns.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "viscompm/core/parameters.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/scene/scene.hpp"

namespace viscompm::study {

enum class StudyMode { systems, steps };
enum class TimeStepUnit { elastic_cfl, seconds, particle_cfl };
enum class RightHandSide { newton, random };

struct StudySettings {
  StudyMode mode = StudyMode::systems;
  std::string scene;                  ///< scene XML (read_study resolves it against the study file)
  RealList cell_sizes;                ///< resolutions Δx [m] (systems; steps: optional)
  RealList time_steps;                ///< Δt, in `time_step_unit` (systems)
  TimeStepUnit time_step_unit = TimeStepUnit::elastic_cfl;
  double time = 0.0;                  ///< advance the scene to this time first [s] (systems)
  RightHandSide right_hand_side = RightHandSide::newton;  ///< −∇E, or a fixed random load (systems)
  StringList solvers;                 ///< solver XML files (resolved against the study file)
  StringList matrix_market_files;     ///< extra problems (resolved against the study file; systems)
  int repetitions = 1;                ///< solves per (problem, configuration); the fastest is kept
  int frames = 2;                     ///< frames per configuration (steps)
  StringList scene_overrides;         ///< "Path/To/Parameter=value" applied to the scene
  std::string output_directory = "output/study";
  bool plot = true;

  /// A configuration of the steps mode: a solver file and overrides of the scene's Newton list.
  struct Configuration {
    std::string label;
    std::string solver;               ///< resolved path
    StringList newton;                ///< "Parameter=value" in the scene's Newton list
  };
  std::vector<Configuration> configurations;  ///< the "Configurations" sublist, else one per solver

  /// A scene of the systems mode, with what the study's top level says unless its sublist says
  /// otherwise.
  struct SceneEntry {
    std::string label;                ///< the sublist's name (empty: the scene's name)
    std::string scene;                ///< resolved path
    double time = 0.0;
    StringList overrides;             ///< "Path/To/Parameter=value"
    RealList cell_sizes;
  };
  std::vector<SceneEntry> scenes;     ///< the "Scenes" sublist, else the top-level Scene (systems)

  static const ParameterTable<StudySettings>& table();
};

/// Reads and validates a study file (InputError with file and parameter on bad input): its
/// scene at every cell size, its solver files and Configurations; the paths it names resolved
/// against it, a missing one naming the study file and the parameter (Scene, Solvers, ...).
StudySettings read_study(const std::string& file, const std::vector<scene::Override>& overrides);

/// Runs the study, logging progress on rank 0. Returns the number of rows written. Every input
/// (MatrixMarket files, the scene's memory at every cell size) is read and checked before an
/// output file is opened, so that bad input (InputError) leaves earlier results as they were.
int run_study(const StudySettings& settings, const std::string& study_file, const parallel::Communicator& comm,
              std::ostream& log);

}  // namespace viscompm::study
