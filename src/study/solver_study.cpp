#include "viscompm/study/solver_study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <ostream>
#include <random>
#include <sstream>

#include "viscompm/core/error.hpp"
#include "viscompm/linalg/matrix_market.hpp"
#include "viscompm/params/parameter_io.hpp"
#include "viscompm/simulation/simulation.hpp"

namespace viscompm::study {

const ParameterTable<StudySettings>& StudySettings::table() {
  static const ParameterTable<StudySettings> t = [] {
    ParameterTable<StudySettings> table;
    using S = StudySettings;
    table.choice(&S::mode, "Mode", StudyMode::systems, {{"systems", StudyMode::systems}, {"steps", StudyMode::steps}},
                 "systems: the same Newton systems under every solver; steps: whole frames of the scene per configuration")
        .string(&S::scene, "Scene", "", {}, "scene whose Newton systems or frames are studied, relative to this file")
        .real_list(&S::cell_sizes, "Cell sizes", {}, Range::positive(),
                   "systems: resolutions Δx [m], one problem each; steps: run every configuration at each (none: the "
                   "scene's own)")
        .real_list(&S::time_steps, "Time steps", {10.0}, Range::positive(), "systems: Δt of the step, in Time step unit")
        .choice(&S::time_step_unit, "Time step unit", TimeStepUnit::elastic_cfl,
                {{"elastic CFL", TimeStepUnit::elastic_cfl}, {"seconds", TimeStepUnit::seconds},
                 {"particle CFL", TimeStepUnit::particle_cfl}},
                "elastic CFL: multiples of Δx/c with c = √((λ+2μ)/ρ) of the stiffest material; particle CFL: "
                "multiples of the step a run takes there (CFL·Δx over the fastest particle, collider or inflow, "
                "at most Max time step)")
        .real(&S::time, "Time", 0.0, Range::non_negative(),
              "systems: advance the scene to this time before taking the system [s]")
        .choice(&S::right_hand_side, "Right-hand side", RightHandSide::newton,
                {{"newton", RightHandSide::newton}, {"random", RightHandSide::random}},
                "systems: newton: the step's −∇E; random: m_i times uniform(−1, 1) per dof, seeded by node "
                "(rank-independent)")
        .string_list(&S::solvers, "Solvers", {}, "solver XML files, relative to this file")
        .string_list(&S::matrix_market_files, "Matrix Market files", {},
                     "systems: extra problems (X.mtx with optional X_rhs.mtx and X_coordinates.mtx)")
        .integer(&S::repetitions, "Repetitions", 1, Range::closed(1, 100), "systems: solves per pair; the fastest is kept")
        .integer(&S::frames, "Frames", 2, Range::at_least(1), "steps: frames of the scene per configuration")
        .string_list(&S::scene_overrides, "Scene overrides", {},
                     "\"Path/To/Parameter=value\" applied to the scene, as --set does")
        .string(&S::output_directory, "Output directory", "output/study", {}, "where the CSV files and plots go")
        .boolean(&S::plot, "Plot", true, "write study.png or steps.png (needs python3-matplotlib)");
    return table;
  }();
  return t;
}

namespace {
struct ConfigurationSettings {
  std::string solver;
  StringList newton;
  static const ParameterTable<ConfigurationSettings>& table() {
    static const ParameterTable<ConfigurationSettings> t = [] {
      ParameterTable<ConfigurationSettings> table;
      using C = ConfigurationSettings;
      table.string(&C::solver, "Solver", "", {}, "solver XML file, relative to the study file")
          .string_list(&C::newton, "Newton", {}, "\"Parameter=value\" overrides of the scene's Newton list");
      return table;
    }();
    return t;
  }
};

// A sublist of "Scenes" (systems mode); what it leaves out comes from the study's top level.
struct SceneEntrySettings {
  std::string scene;
  double time = 0.0;
  StringList overrides;
  double smallest_cell = 0.0;
  static const ParameterTable<SceneEntrySettings>& table() {
    static const ParameterTable<SceneEntrySettings> t = [] {
      ParameterTable<SceneEntrySettings> table;
      using E = SceneEntrySettings;
      table.string(&E::scene, "Scene", "", {}, "scene file, relative to the study file")
          .real(&E::time, "Time", -1.0, Range::at_least(-1.0), "advance the scene to this time first [s] (-1: the study's Time)")
          .string_list(&E::overrides, "Scene overrides", {},
                       "\"Path/To/Parameter=value\" applied to the scene after the study's own Scene overrides")
          .real(&E::smallest_cell, "Smallest cell size", 0.0, Range::non_negative(),
                "leave out the study's Cell sizes below this one [m] (for a scene too large at those sizes)");
      return table;
    }();
    return t;
  }
};

// An Array(string) of overrides cannot hold braces (Teuchos rejects them) and is split at every
// comma: a vector value is written in parentheses ("Bodies/a/Center=(1, 2, 3)"), its pieces are
// joined again until the parentheses balance, and the parentheses become the braces --set takes.
StringList rejoin_vectors(const StringList& pieces) {
  StringList joined;
  int depth = 0;
  for (const auto& piece : pieces) {
    if (depth > 0) joined.back() += ", " + piece;
    else joined.push_back(piece);
    for (char c : piece) depth += c == '(' ? 1 : c == ')' ? -1 : 0;
  }
  for (auto& o : joined)
    for (char& c : o) c = c == '(' ? '{' : c == ')' ? '}' : c;
  return joined;
}

std::string relative_to(const std::string& file, const std::string& path) {
  const std::filesystem::path p(path);
  return p.is_absolute() ? path : (std::filesystem::path(file).parent_path() / p).lexically_normal().string();
}

// A file the study names at `parameter`, resolved against the study file; it must exist.
std::string study_input(const std::string& study_file, const std::string& parameter, const std::string& path) {
  const std::string resolved = relative_to(study_file, path);
  if (!std::filesystem::is_regular_file(resolved))
    throw parameter_error(study_file, parameter, "cannot open '" + resolved + "'");
  return resolved;
}

std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// A value as --set text that reads back as the same double.
std::string exact(double x) {
  std::ostringstream s;
  s << std::setprecision(17) << x;
  return s.str();
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A scene of a systems study at cell size h: its overrides, then the cell size, so that what
// derives from it (meshes' voxels, disc nozzles, the size checks) follows. Read by every rank of
// `comm` together when given (stop requests agreed between meshes), else by this rank alone.
scene::SceneConfig scene_at(const StudySettings::SceneEntry& entry, double h, const parallel::Communicator* comm = nullptr) {
  std::vector<scene::Override> overrides;
  for (const auto& o : entry.overrides) overrides.push_back(scene::Override::parse(o));
  overrides.push_back({"Grid/Cell size", exact(h)});
  return comm ? scene::read_scene(entry.scene, overrides, *comm) : scene::read_scene(entry.scene, overrides);
}

// The scene of a steps configuration: the study's scene overrides, the cell size h (0: as they
// leave it), then the configuration's Newton overrides.
scene::SceneConfig scene_for(const StudySettings& settings, const StudySettings::Configuration& configuration,
                             double h, const parallel::Communicator* comm = nullptr) {
  std::vector<scene::Override> overrides;
  for (const auto& o : settings.scene_overrides) overrides.push_back(scene::Override::parse(o));
  if (h > 0.0) overrides.push_back({"Grid/Cell size", exact(h)});
  for (const auto& o : configuration.newton) {
    scene::Override newton = scene::Override::parse(o);
    newton.path = "Newton/" + newton.path;
    overrides.push_back(newton);
  }
  return comm ? scene::read_scene(settings.scene, overrides, *comm) : scene::read_scene(settings.scene, overrides);
}

// The output directory, created on rank 0; every rank learns whether it could be.
void create_output_directory(const StudySettings& settings, const std::string& study_file,
                             const parallel::Communicator& comm) {
  std::error_code error;
  if (comm.is_root()) std::filesystem::create_directories(settings.output_directory, error);
  if (comm.any(comm.is_root() && (error || !std::filesystem::is_directory(settings.output_directory))))
    throw parameter_error(study_file, "Output directory", "cannot create '" + settings.output_directory + "'");
}

// Opens DIR/NAME on rank 0 for writing (truncating it); every rank learns whether it could.
void open_csv(std::ofstream& out, const std::string& directory, const std::string& name, const std::string& study_file,
              const parallel::Communicator& comm) {
  if (comm.is_root()) out.open(std::filesystem::path(directory) / name);
  if (comm.any(comm.is_root() && !out))
    throw parameter_error(study_file, "Output directory", "cannot write " + name + " in '" + directory + "'");
}

struct Row {
  std::string problem;
  double resolution = 0.0;
  std::int64_t dofs = 0, nonzeros = 0;
  linalg::LinearSolveReport report;
  double apply_seconds = 0.0;                 // one application of H
  double preconditioner_apply_seconds = 0.0;  // one application of the preconditioner (a V-cycle)
  double peak_memory = 0.0;                   // bytes, the largest rank's, during this configuration
};

class Writer {
 public:
  Writer(const std::string& directory, const std::string& study_file, const parallel::Communicator& comm)
      : root_(comm.is_root()), ranks_(comm.size()) {
    open_csv(study_, directory, "study.csv", study_file, comm);
    open_csv(operators_, directory, "operators.csv", study_file, comm);
    if (!root_) return;
    study_ << "problem,resolution,dofs,nonzeros,ranks,preconditioner,setup_seconds,solve_seconds,iterations,"
              "relative_residual,converged,operator_seconds,apply_seconds,preconditioner_apply_seconds,"
              "peak_memory_mib\n";
    operators_ << "problem,resolution,dofs,ranks,preconditioner,operator,assembly_seconds,apply_seconds\n";
  }
  void row(const Row& r) {
    ++rows_;
    if (!root_) return;
    study_ << '"' << r.problem << "\"," << r.resolution << ',' << r.dofs << ',' << r.nonzeros << ',' << ranks_ << ",\""
           << r.report.preconditioner << "\"," << r.report.setup_seconds << ',' << r.report.solve_seconds << ','
           << r.report.iterations << ',' << r.report.relative_residual << ',' << (r.report.converged ? 1 : 0) << ','
           << r.report.operator_seconds << ',' << r.apply_seconds << ',' << r.preconditioner_apply_seconds << ','
           << r.peak_memory / (1024.0 * 1024.0) << '\n';
    study_.flush();
  }
  void operator_row(const Row& r, const std::string& form) {
    if (!root_) return;
    operators_ << '"' << r.problem << "\"," << r.resolution << ',' << r.dofs << ',' << ranks_ << ",\""
               << r.report.preconditioner << "\"," << form << ',' << r.report.operator_seconds << ','
               << r.apply_seconds << '\n';
    operators_.flush();
  }
  int rows() const { return rows_; }

 private:
  bool root_;
  int ranks_;
  int rows_ = 0;
  std::ofstream study_, operators_;
};

void log_row(std::ostream& log, const Row& row) {
  const auto& r = row.report;
  log << std::setw(28) << std::left << row.problem << " dx=" << row.resolution << " dofs=" << row.dofs << "  "
      << std::setw(22) << r.preconditioner << std::right << " it=" << std::setw(5) << r.iterations
      << " operator=" << std::setprecision(3) << r.operator_seconds << "s setup=" << r.setup_seconds
      << "s solve=" << r.solve_seconds << "s apply=" << row.apply_seconds * 1e3 << "ms preconditioner="
      << row.preconditioner_apply_seconds * 1e3 << "ms peak=" << std::setprecision(4)
      << row.peak_memory / (1024.0 * 1024.0) << "MiB" << (r.converged ? "" : "  NOT CONVERGED")
      << std::setprecision(6) << std::endl;
  if (!r.failure.empty()) log << "  " << r.failure.substr(0, r.failure.find('\n')) << std::endl;
}

// What a systems study reads, all of it before any output file is opened.
struct SystemsInputs {
  /// One per scene entry and cell size, with its entry.
  std::vector<std::pair<const StudySettings::SceneEntry*, scene::SceneConfig>> scenes;
  std::vector<linalg::SolverConfiguration> configs;
  std::vector<std::unique_ptr<linalg::MatrixMarketProblem>> problems;
};

SystemsInputs read_systems_inputs(const StudySettings& settings, const parallel::Communicator& comm) {
  SystemsInputs inputs;
  for (const auto& s : settings.solvers) inputs.configs.push_back(linalg::SolverConfiguration::read(s));
  for (const auto& entry : settings.scenes)
    for (double h : entry.cell_sizes) {
      inputs.scenes.emplace_back(&entry, scene_at(entry, h, &comm));
      simulation::check_memory(inputs.scenes.back().second, comm);
    }
  for (const auto& file : settings.matrix_market_files)
    inputs.problems.push_back(std::make_unique<linalg::MatrixMarketProblem>(file, comm));
  return inputs;
}

// One configuration on the step's system: its own operator (assembly or matrix-free set-up),
// preconditioner and solve, the fastest of the repetitions; a failed set-up is a row with
// converged = 0.
void solve_scene_system(const StudySettings& settings, const linalg::SolverConfiguration& config,
                        simulation::TimeIntegrator& integrator, const simulation::StepObjective& objective,
                        const NodeVectorField& rhs, Row& row, Writer& writer, const parallel::Communicator& comm,
                        std::ostream& log) {
  parallel::reset_peak_memory();
  linalg::NewtonSystem system(integrator.node_space(), config);
  row.dofs = system.global_rows();
  row.apply_seconds = row.preconditioner_apply_seconds = 0.0;
  linalg::LinearSolveReport best;
  const auto total = [](const linalg::LinearSolveReport& r) { return r.operator_seconds + r.setup_seconds + r.solve_seconds; };
  try {
    for (int k = 0; k < settings.repetitions; ++k) {
      const double operator_seconds = system.assemble(*objective.potential, objective.initial_guess, true);
      const double setup_seconds = system.precondition();
      NodeVectorField dv;
      auto report = system.solve(rhs, dv);
      report.operator_seconds = operator_seconds;
      report.setup_seconds = setup_seconds;
      if (k == 0 || total(report) < total(best)) best = report;
    }
    row.apply_seconds = system.time_apply(5);
    row.preconditioner_apply_seconds = system.time_preconditioner(5);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    best = linalg::LinearSolveReport{};
    best.preconditioner = config.label();
    if (comm.is_root()) log << "  " << config.label() << " failed: " << e.what() << "\n";
  }
  if (!system.matrix_free()) row.nonzeros = system.global_nonzeros();
  row.report = best;
  row.peak_memory = comm.max(parallel::peak_memory());
  writer.row(row);
  writer.operator_row(row, system.matrix_free() ? "matrix-free" : "assembled");
  if (comm.is_root()) log_row(log, row);
}

// The right-hand side of the step's system: −∇E, or m_i times uniform(−1, 1) per dof seeded by
// the node (rank-independent). False if the initial guess is infeasible (no system).
bool right_hand_side(const StudySettings& settings, simulation::TimeIntegrator& integrator,
                     const simulation::StepObjective& objective, NodeVectorField& rhs) {
  if (!integrator.first_right_hand_side(objective, rhs)) return false;
  if (settings.right_hand_side != RightHandSide::random) return true;
  const auto& layout = integrator.layout();
  for (std::size_t i = 0; i < layout.owned_count; ++i) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(layout.nodes[i]));
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    rhs[i] = objective.constraints.projection[i] * (integrator.grid_mass()[i] * Vec3(u(rng), u(rng), u(rng)));
  }
  return true;
}

// The first Newton system of a scene at each cell size and Δt, under every configuration.
void study_scene_systems(const StudySettings& settings, const SystemsInputs& inputs, const parallel::Communicator& comm,
                         Writer& writer, std::ostream& log) {
  for (const auto& [entry, scene] : inputs.scenes) {
    // Advance with the scene's own solver, then take the step's Newton system at several Δt.
    simulation::Simulation sim(scene, scene::solver_configuration(scene), comm);
    if (entry->time > 0.0) {
      simulation::RunSummary summary;
      sim.advance_to(entry->time, summary);
    }
    double wave_speed = 0.0;
    for (const auto& m : sim.materials()) wave_speed = std::max(wave_speed, m->wave_speed());
    const double run_step = sim.suggested_time_step();
    const TimeStepUnit unit = settings.time_step_unit;
    auto seconds = [&](double step) {
      return unit == TimeStepUnit::elastic_cfl ? step * sim.grid().dx / wave_speed
             : unit == TimeStepUnit::particle_cfl ? step * run_step
                                                  : step;
    };
    const char* unit_name = unit == TimeStepUnit::elastic_cfl ? "xCFL" : unit == TimeStepUnit::particle_cfl ? "xrun" : "s";
    double largest_step = 0.0;
    for (double step : settings.time_steps) largest_step = std::max(largest_step, seconds(step));
    auto& integrator = sim.integrator();
    integrator.prepare(sim.particles(), largest_step);
    for (double step : settings.time_steps) {
      const auto objective = integrator.build_objective(sim.particles(), sim.time(), seconds(step));
      Row row;
      row.problem = (entry->label.empty() ? scene.name : entry->label) + " t=" + number(sim.time()) + " dt=" + number(seconds(step)) + "s (" +
                    number(step) + unit_name + ")";
      row.resolution = scene.grid.cell_size;
      row.nonzeros = -1;
      NodeVectorField rhs;
      if (!right_hand_side(settings, integrator, *objective, rhs)) {
        // No Newton system here: every configuration gets a failed row.
        if (comm.is_root()) log << row.problem << " dx=" << row.resolution << ": infeasible initial guess, no system\n";
        for (const auto& config : inputs.configs) {
          row.report = linalg::LinearSolveReport{};
          row.report.preconditioner = config.label();
          writer.row(row);
        }
        continue;
      }
      for (const auto& config : inputs.configs)
        solve_scene_system(settings, config, integrator, *objective, rhs, row, writer, comm, log);
    }
  }
}

void study_matrix_market(const SystemsInputs& inputs, const StudySettings& settings,
                         const parallel::Communicator& comm, Writer& writer, std::ostream& log) {
  for (std::size_t k = 0; k < inputs.problems.size(); ++k) {
    const linalg::MatrixMarketProblem& problem = *inputs.problems[k];
    for (const auto& config : inputs.configs) {
      if (config.matrix_free()) continue;  // a matrix-free operator needs the scene's particles
      Row row;
      row.problem = std::filesystem::path(settings.matrix_market_files[k]).stem().string();
      row.dofs = problem.rows();
      row.nonzeros = problem.nonzeros();
      linalg::MatrixMarketSolve solved;
      parallel::reset_peak_memory();
      try {
        solved = problem.solve(config);
      } catch (const InputError&) {
        throw;
      } catch (const std::exception& e) {
        solved.report.preconditioner = config.label();  // a failed set-up is a row, not a crash
        if (comm.is_root()) log << "  " << config.label() << " failed: " << e.what() << "\n";
      }
      row.report = solved.report;
      row.apply_seconds = comm.max(solved.apply_seconds);
      row.preconditioner_apply_seconds = comm.max(solved.preconditioner_apply_seconds);
      row.peak_memory = comm.max(parallel::peak_memory());
      writer.row(row);
      writer.operator_row(row, "assembled");
      if (comm.is_root()) log_row(log, row);
    }
  }
}

// One row of steps.csv: the configuration's frames, its counts and where the time went (the
// slowest rank's phase times).
void write_steps_row(std::ofstream& out, const StudySettings& settings, const StudySettings::Configuration& configuration,
                     double cell_size, const simulation::RunSummary& summary, double wall,
                     const parallel::Communicator& comm) {
  const double operator_seconds = comm.max(summary.operator_seconds);
  const double setup_seconds = comm.max(summary.preconditioner_seconds);
  const double cg_seconds = comm.max(summary.cg_seconds);
  const double line_search_seconds = comm.max(summary.line_search_seconds);
  if (!comm.is_root()) return;
  out << '"' << configuration.label << "\",\"" << std::filesystem::path(configuration.solver).filename().string()
      << "\"," << settings.frames << ',' << summary.steps << ',' << summary.newton_iterations << ','
      << summary.linear_iterations << ',' << summary.assemblies << ',' << summary.preconditioner_setups << ','
      << summary.graph_builds << ',' << summary.retries << ',' << wall << ',' << wall / settings.frames << ','
      << operator_seconds << ',' << setup_seconds << ',' << cg_seconds << ',' << line_search_seconds << ','
      << comm.size() << ',' << cell_size << '\n';
  out.flush();
}

// Whole frames of the scene under each configuration (at each cell size): steps.csv, one row per run.
int study_steps(const StudySettings& settings, const std::string& study_file, const parallel::Communicator& comm,
                std::ostream& log) {
  std::vector<scene::SceneConfig> scenes;
  std::vector<const StudySettings::Configuration*> configurations;
  const std::vector<double> cell_sizes = settings.cell_sizes.empty() ? std::vector<double>{0.0} : settings.cell_sizes;
  for (double h : cell_sizes)
    for (const auto& configuration : settings.configurations) {
      scenes.push_back(scene_for(settings, configuration, h, &comm));
      configurations.push_back(&configuration);
      simulation::check_memory(scenes.back(), comm);
    }
  std::ofstream out;
  open_csv(out, settings.output_directory, "steps.csv", study_file, comm);
  out << std::setprecision(9)
      << "configuration,solver,frames,steps,newton_iterations,cg_iterations,assemblies,preconditioner_setups,"
         "graph_builds,retries,wall_seconds,seconds_per_frame,operator_seconds,preconditioner_seconds,cg_seconds,"
         "line_search_seconds,ranks,cell_size\n";
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const auto& configuration = *configurations[k];
    simulation::Simulation sim(scenes[k], linalg::SolverConfiguration::read(configuration.solver), comm);
    simulation::RunSummary summary;
    comm.barrier();
    const auto start = std::chrono::steady_clock::now();
    for (int frame = 1; frame <= settings.frames; ++frame) {
      sim.advance_to(frame / scenes[k].simulation.frame_rate, summary);
      if (comm.is_root())
        log << configuration.label << " (Δx " << scenes[k].grid.cell_size << "): frame " << frame << "/" << settings.frames << ", " << summary.steps
            << " steps, " << summary.newton_iterations << " Newton, " << summary.linear_iterations << " CG, "
            << std::setprecision(4) << seconds_since(start) << " s" << std::setprecision(6) << std::endl;
    }
    write_steps_row(out, settings, configuration, scenes[k].grid.cell_size, summary, comm.max(seconds_since(start)),
                    comm);
  }
  return static_cast<int>(scenes.size());
}

// The configurations of the steps mode: the "Configurations" sublist (a sublist each), else one
// per solver file; every one's scene and solver file read now, before any run starts.
void read_configurations(const Teuchos::ParameterList& list, const std::string& file, StudySettings& settings) {
  if (list.isSublist("Configurations")) {
    const auto& configurations = list.sublist("Configurations");
    for (auto it = configurations.begin(); it != configurations.end(); ++it) {
      const std::string& name = configurations.name(it);
      const std::string path = "Configurations/" + name;
      if (!configurations.isSublist(name)) throw parameter_error(file, path, "expected a sublist");
      const auto c = ConfigurationSettings::table().parse(
          params::read_parameters(configurations.sublist(name), ConfigurationSettings::table().specs(), file, path));
      if (c.solver.empty()) throw parameter_error(file, path + "/Solver", "give a solver file");
      settings.configurations.push_back({name, study_input(file, path + "/Solver", c.solver), c.newton});
    }
  } else {
    for (const auto& path : settings.solvers)
      settings.configurations.push_back({std::filesystem::path(path).stem().string(), path, {}});
  }
  if (settings.configurations.empty())
    throw parameter_error(file, "Configurations", "give at least one configuration (or Solvers)");
  for (const auto& o : settings.scene_overrides) {
    try {
      (void)scene::Override::parse(o);
    } catch (const InputError&) {
      throw parameter_error(file, "Scene overrides", "'" + o + "' is not Path/To/Parameter=value");
    }
  }
  for (double h : settings.cell_sizes.empty() ? std::vector<double>{0.0} : settings.cell_sizes)
    for (const auto& c : settings.configurations) (void)scene_for(settings, c, h);
  for (const auto& c : settings.configurations) {
    (void)linalg::SolverConfiguration::read(c.solver);
  }
}
}  // namespace

namespace {
// The scenes of the systems mode: the "Scenes" sublist (a sublist each, what it leaves out taken
// from the top level), else the top-level Scene; each with at least one cell size.
void read_scene_entries(const Teuchos::ParameterList& list, const std::string& file, StudySettings& settings) {
  const auto checked_overrides = [&](const StringList& overrides, const std::string& parameter) {
    for (const auto& o : overrides) {
      try {
        (void)scene::Override::parse(o);
      } catch (const InputError&) {
        throw parameter_error(file, parameter, "'" + o + "' is not Path/To/Parameter=value");
      }
    }
    return overrides;
  };
  const StringList top_overrides = checked_overrides(settings.scene_overrides, "Scene overrides");
  if (list.isSublist("Scenes")) {
    if (!settings.scene.empty())
      throw parameter_error(file, "Scene", "give either Scene or a Scenes sublist, not both");
    const auto& scenes = list.sublist("Scenes");
    for (auto it = scenes.begin(); it != scenes.end(); ++it) {
      const std::string& name = scenes.name(it);
      const std::string path = "Scenes/" + name;
      if (!scenes.isSublist(name)) throw parameter_error(file, path, "expected a sublist");
      const auto e = SceneEntrySettings::table().parse(
          params::read_parameters(scenes.sublist(name), SceneEntrySettings::table().specs(), file, path));
      if (e.scene.empty()) throw parameter_error(file, path + "/Scene", "give a scene file");
      StudySettings::SceneEntry entry{name, study_input(file, path + "/Scene", e.scene), e.time < 0.0 ? settings.time : e.time,
                                      top_overrides, {}};
      for (const auto& o : checked_overrides(rejoin_vectors(e.overrides), path + "/Scene overrides")) entry.overrides.push_back(o);
      if (settings.cell_sizes.empty()) throw parameter_error(file, "Cell sizes", "give at least one resolution");
      for (double h : settings.cell_sizes)
        if (h >= e.smallest_cell) entry.cell_sizes.push_back(h);
      settings.scenes.push_back(entry);
    }
    if (settings.scenes.empty()) throw parameter_error(file, "Scenes", "give at least one scene");
  } else if (!settings.scene.empty()) {
    if (settings.cell_sizes.empty()) throw parameter_error(file, "Cell sizes", "give at least one resolution");
    settings.scenes.push_back({"", settings.scene, settings.time, top_overrides, settings.cell_sizes});
  }
}
}  // namespace

StudySettings read_study(const std::string& file, const std::vector<scene::Override>& overrides) {
  auto list = params::read_xml_file(file);
  const auto& specs = StudySettings::table().specs();
  for (const auto& o : overrides) {
    const auto spec = std::find_if(specs.begin(), specs.end(), [&](const auto& s) { return s.name == o.path; });
    if (spec == specs.end()) throw InputError(file + ": --set '" + o.path + "': unknown parameter");
    try {
      params::set_entry(*list, o.path, params::parse_value(*spec, o.value));
    } catch (const InputError& e) {
      throw InputError(file + ": --set '" + o.path + "': " + e.what());
    }
  }
  StudySettings settings =
      StudySettings::table().parse(params::read_parameters(*list, specs, file, "", {"Configurations", "Scenes"}));
  settings.scene_overrides = rejoin_vectors(settings.scene_overrides);
  if (settings.scene.empty() && settings.matrix_market_files.empty() && !list->isSublist("Scenes"))
    throw parameter_error(file, "Scene", "a study needs a scene (or Scenes) or Matrix Market files");
  // The files the study names, resolved against it: a missing one names the study's parameter.
  if (!settings.scene.empty()) settings.scene = study_input(file, "Scene", settings.scene);
  for (auto& s : settings.solvers) s = study_input(file, "Solvers", s);
  for (auto& m : settings.matrix_market_files) m = study_input(file, "Matrix Market files", m);
  if (settings.mode == StudyMode::steps) {
    if (settings.scene.empty()) throw parameter_error(file, "Scene", "the steps mode needs a scene");
    if (list->isSublist("Scenes")) throw parameter_error(file, "Scenes", "the steps mode takes one Scene");
    read_configurations(*list, file, settings);
    return settings;
  }
  read_scene_entries(*list, file, settings);
  if (settings.solvers.empty()) throw parameter_error(file, "Solvers", "give at least one solver file");
  for (const auto& entry : settings.scenes)
    for (double h : entry.cell_sizes) (void)scene_at(entry, h);
  for (const auto& s : settings.solvers)
    if (linalg::SolverConfiguration::read(s).is_choice())
      throw parameter_error(file, "Solvers", "'" + s + "' is a measured choice, which picks a configuration per time "
                                             "step: a systems study solves each system with one (list its candidates)");
  return settings;
}

int run_study(const StudySettings& settings, const std::string& study_file, const parallel::Communicator& comm,
              std::ostream& log) {
  if (settings.mode == StudyMode::steps) {
    create_output_directory(settings, study_file, comm);
    return study_steps(settings, study_file, comm, log);
  }
  const SystemsInputs inputs = read_systems_inputs(settings, comm);
  create_output_directory(settings, study_file, comm);
  Writer writer(settings.output_directory, study_file, comm);  // truncates study.csv, operators.csv
  study_scene_systems(settings, inputs, comm, writer, log);
  study_matrix_market(inputs, settings, comm, writer, log);
  return writer.rows();
}

}  // namespace viscompm::study
