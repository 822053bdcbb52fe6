#include "viscompm/study/solver_study.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
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
    table.string(&S::mode, "Mode", "systems", {"systems", "steps"},
                 "systems: the same Newton systems under every solver; steps: whole frames of the scene per configuration")
        .string(&S::scene, "Scene", "", {}, "scene whose Newton systems or frames are studied, relative to this file")
        .real_list(&S::cell_sizes, "Cell sizes", {}, Range::positive(), "systems: resolutions Δx [m], one problem each")
        .real_list(&S::time_steps, "Time steps", {10.0}, Range::positive(), "systems: Δt of the step, in Time step unit")
        .string(&S::time_step_unit, "Time step unit", "elastic CFL", {"elastic CFL", "seconds"},
                "elastic CFL: multiples of Δx/c with c = √((λ+2μ)/ρ) of the stiffest material")
        .real(&S::time, "Time", 0.0, Range::non_negative(),
              "systems: advance the scene to this time before taking the system [s]")
        .string(&S::right_hand_side, "Right-hand side", "newton", {"newton", "random"},
                "systems: newton: the step's −∇E; random: m_i times uniform(−1, 1) per dof, seeded by node "
                "(rank-independent)")
        .string_list(&S::solvers, "Solvers", {}, "solver XML files, relative to this file")
        .string_list(&S::matrix_market_files, "Matrix Market files", {},
                     "systems: extra problems (X.mtx with optional X_rhs.mtx and X_coordinates.mtx)")
        .integer(&S::repetitions, "Repetitions", 1, Range::closed(1, 100), "systems: solves per pair; the fastest is kept")
        .integer(&S::frames, "Frames", 2, Range::at_least(1), "steps: frames of the scene per configuration")
        .string_list(&S::scene_overrides, "Scene overrides", {},
                     "steps: \"Path/To/Parameter=value\" applied to the scene, as --set does")
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

std::string relative_to(const std::string& file, const std::string& path) {
  const std::filesystem::path p(path);
  return p.is_absolute() ? path : (std::filesystem::path(file).parent_path() / p).lexically_normal().string();
}

std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct Row {
  std::string problem;
  double resolution = 0.0;
  std::int64_t dofs = 0, nonzeros = 0;
  linalg::LinearSolveReport report;
};

class Writer {
 public:
  Writer(const std::string& directory, bool root, int ranks) : root_(root), ranks_(ranks) {
    if (!root_) return;
    study_.open(std::filesystem::path(directory) / "study.csv");
    operators_.open(std::filesystem::path(directory) / "operators.csv");
    if (!study_ || !operators_) throw InputError("cannot write to " + directory);
    study_ << "problem,resolution,dofs,nonzeros,ranks,preconditioner,setup_seconds,solve_seconds,iterations,"
              "relative_residual,converged,operator_seconds\n";
    operators_ << "problem,resolution,dofs,ranks,preconditioner,operator,assembly_seconds,apply_seconds\n";
  }
  void row(const Row& r) {
    ++rows_;
    if (!root_) return;
    study_ << '"' << r.problem << "\"," << r.resolution << ',' << r.dofs << ',' << r.nonzeros << ',' << ranks_ << ",\""
           << r.report.preconditioner << "\"," << r.report.setup_seconds << ',' << r.report.solve_seconds << ','
           << r.report.iterations << ',' << r.report.relative_residual << ',' << (r.report.converged ? 1 : 0) << ','
           << r.report.operator_seconds << '\n';
    study_.flush();
  }
  void operator_row(const Row& r, const std::string& form, double apply) {
    if (!root_) return;
    operators_ << '"' << r.problem << "\"," << r.resolution << ',' << r.dofs << ',' << ranks_ << ",\""
               << r.report.preconditioner << "\"," << form << ',' << r.report.operator_seconds << ',' << apply << '\n';
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
      << "s solve=" << r.solve_seconds << "s" << (r.converged ? "" : "  NOT CONVERGED") << std::setprecision(6)
      << std::endl;
  if (!r.failure.empty()) log << "  " << r.failure.substr(0, r.failure.find('\n')) << std::endl;
}

// The first Newton system of a scene at each cell size and Δt, under every configuration. Each
// configuration prepares its own operator (assembly or matrix-free set-up), timed.
void study_scene_systems(const StudySettings& settings, const std::string& study_file,
                         const std::vector<linalg::SolverConfiguration>& configs, const parallel::Communicator& comm,
                         Writer& writer, std::ostream& log) {
  for (double h : settings.cell_sizes) {
    // The cell size as an override, so that what derives from it (meshes' voxels, nozzles) follows.
    const scene::SceneConfig scene =
        scene::read_scene(relative_to(study_file, settings.scene), {{"Grid/Cell size", number(h)}});
    // Advance with the scene's own solver, then take the step's Newton system at several Δt.
    simulation::Simulation sim(scene, scene::solver_configuration(scene), comm);
    if (settings.time > 0.0) {
      simulation::RunSummary summary;
      sim.advance_to(settings.time, summary);
    }
    double wave_speed = 0.0;
    for (const auto& m : sim.materials()) wave_speed = std::max(wave_speed, m->wave_speed());
    const bool cfl = settings.time_step_unit == "elastic CFL";
    auto seconds = [&](double step) { return cfl ? step * sim.grid().dx / wave_speed : step; };
    double largest_step = 0.0;
    for (double step : settings.time_steps) largest_step = std::max(largest_step, seconds(step));
    auto& integrator = sim.integrator();
    integrator.prepare(sim.particles(), largest_step);
    for (double step : settings.time_steps) {
      const auto objective = integrator.build_objective(sim.particles(), sim.time(), seconds(step));
      Row row;
      row.problem = scene.name + " t=" + number(sim.time()) + " dt=" + number(step) + (cfl ? "xCFL" : "s");
      row.resolution = h;
      NodeVectorField rhs;
      if (!integrator.first_right_hand_side(*objective, rhs)) {
        // No Newton system here: every configuration gets a failed row.
        if (comm.is_root()) log << row.problem << " dx=" << h << ": infeasible initial guess, no system\n";
        for (const auto& config : configs) {
          row.report = linalg::LinearSolveReport{};
          row.report.preconditioner = config.label();
          writer.row(row);
        }
        continue;
      }
      const auto& layout = integrator.layout();
      if (settings.right_hand_side == "random")
        for (std::size_t i = 0; i < layout.owned_count; ++i) {
          std::mt19937_64 rng(static_cast<std::uint64_t>(layout.nodes[i]));
          std::uniform_real_distribution<double> u(-1.0, 1.0);
          rhs[i] = objective->constraints.projection[i] * (integrator.grid_mass()[i] * Vec3(u(rng), u(rng), u(rng)));
        }
      std::int64_t nonzeros = -1;
      for (const auto& config : configs) {
        linalg::NewtonSystem system(integrator.node_space(), config);
        row.dofs = system.global_rows();
        double apply = 0.0;
        linalg::LinearSolveReport best;
        try {
          for (int k = 0; k < settings.repetitions; ++k) {
            const double operator_seconds = system.assemble(*objective->potential, objective->initial_guess, true);
            const double setup_seconds = system.precondition();
            NodeVectorField dv;
            auto report = system.solve(rhs, dv);
            report.operator_seconds = operator_seconds;
            report.setup_seconds = setup_seconds;
            const auto total = [](const linalg::LinearSolveReport& r) {
              return r.operator_seconds + r.setup_seconds + r.solve_seconds;
            };
            if (k == 0 || total(report) < total(best)) best = report;
          }
          apply = system.time_apply(5);
        } catch (const InputError&) {
          throw;
        } catch (const std::exception& e) {
          best = linalg::LinearSolveReport{};  // a failed set-up is a row with converged = 0
          best.preconditioner = config.label();
          if (comm.is_root()) log << "  " << config.label() << " failed: " << e.what() << "\n";
        }
        if (!system.matrix_free()) nonzeros = system.global_nonzeros();
        row.nonzeros = nonzeros;
        row.report = best;
        writer.row(row);
        writer.operator_row(row, system.matrix_free() ? "matrix-free" : "assembled", apply);
        if (comm.is_root()) log_row(log, row);
      }
    }
  }
}

void study_matrix_market(const StudySettings& settings, const std::string& study_file,
                         const std::vector<linalg::SolverConfiguration>& configs, const parallel::Communicator& comm,
                         Writer& writer, std::ostream& log) {
  for (const auto& file : settings.matrix_market_files) {
    const std::string path = relative_to(study_file, file);
    const linalg::MatrixMarketProblem problem(path, comm);
    for (const auto& config : configs) {
      if (config.matrix_free()) continue;  // a matrix-free operator needs the scene's particles
      Row row;
      row.problem = std::filesystem::path(path).stem().string();
      row.dofs = problem.rows();
      row.nonzeros = problem.nonzeros();
      linalg::MatrixMarketSolve solved;
      try {
        solved = problem.solve(config);
      } catch (const InputError&) {
        throw;
      } catch (const std::exception& e) {
        solved.report.preconditioner = config.label();  // a failed set-up is a row, not a crash
        if (comm.is_root()) log << "  " << config.label() << " failed: " << e.what() << "\n";
      }
      row.report = solved.report;
      writer.row(row);
      writer.operator_row(row, "assembled", solved.apply_seconds);
      if (comm.is_root()) log_row(log, row);
    }
  }
}

// Whole frames of the scene under each configuration: steps.csv, one row per configuration.
int study_steps(const StudySettings& settings, const std::string& study_file, const parallel::Communicator& comm,
                std::ostream& log) {
  std::ofstream out;
  if (comm.is_root()) {
    out.open(std::filesystem::path(settings.output_directory) / "steps.csv");
    if (!out) throw InputError(study_file + ": parameter 'Output directory': cannot write steps.csv there");
    out << std::setprecision(9);
    out << "configuration,solver,frames,steps,newton_iterations,cg_iterations,assemblies,preconditioner_setups,"
           "graph_builds,retries,wall_seconds,seconds_per_frame,operator_seconds,preconditioner_seconds,cg_seconds,"
           "line_search_seconds,ranks\n";
  }
  int rows = 0;
  for (const auto& configuration : settings.configurations) {
    std::vector<scene::Override> overrides;
    for (const auto& o : settings.scene_overrides) overrides.push_back(scene::Override::parse(o));
    for (const auto& o : configuration.newton) {
      scene::Override newton = scene::Override::parse(o);
      newton.path = "Newton/" + newton.path;
      overrides.push_back(newton);
    }
    const scene::SceneConfig scene = scene::read_scene(relative_to(study_file, settings.scene), overrides);
    const auto solver = linalg::SolverConfiguration::read(configuration.solver);
    simulation::Simulation sim(scene, solver, comm);
    simulation::RunSummary summary;
    comm.barrier();
    const auto start = std::chrono::steady_clock::now();
    for (int frame = 1; frame <= settings.frames; ++frame) {
      sim.advance_to(frame / scene.simulation.frame_rate, summary);
      if (comm.is_root())
        log << configuration.label << ": frame " << frame << "/" << settings.frames << ", " << summary.steps
            << " steps, " << summary.newton_iterations << " Newton, " << summary.linear_iterations << " CG, "
            << std::setprecision(4) << seconds_since(start) << " s" << std::setprecision(6) << std::endl;
    }
    const double wall = comm.max(seconds_since(start));
    // Phase times: the slowest rank's.
    const double operator_seconds = comm.max(summary.operator_seconds);
    const double setup_seconds = comm.max(summary.preconditioner_seconds);
    const double cg_seconds = comm.max(summary.cg_seconds);
    const double line_search_seconds = comm.max(summary.line_search_seconds);
    if (comm.is_root()) {
      out << '"' << configuration.label << "\",\"" << std::filesystem::path(configuration.solver).filename().string()
          << "\"," << settings.frames << ',' << summary.steps << ',' << summary.newton_iterations << ','
          << summary.linear_iterations << ',' << summary.assemblies << ',' << summary.preconditioner_setups << ','
          << summary.graph_builds << ',' << summary.retries << ',' << wall << ',' << wall / settings.frames << ','
          << operator_seconds << ',' << setup_seconds << ',' << cg_seconds << ',' << line_search_seconds << ','
          << comm.size() << '\n';
      out.flush();
    }
    ++rows;
  }
  return rows;
}
}  // namespace

StudySettings read_study(const std::string& file, const std::vector<scene::Override>& overrides) {
  auto list = params::read_xml_file(file);
  const auto& specs = StudySettings::table().specs();
  for (const auto& o : overrides) {
    const ParameterSpec* spec = nullptr;
    for (const auto& s : specs)
      if (s.name == o.path) spec = &s;
    if (spec == nullptr) throw InputError(file + ": --set '" + o.path + "': unknown parameter");
    params::set_entry(*list, o.path, params::parse_value(*spec, o.value));
  }
  StudySettings settings =
      StudySettings::table().parse(params::read_parameters(*list, specs, file, "", {"Configurations"}));
  if (settings.scene.empty() && settings.matrix_market_files.empty())
    throw InputError(file + ": parameter 'Scene': a study needs a scene or Matrix Market files");
  if (settings.mode == "steps") {
    if (settings.scene.empty()) throw InputError(file + ": parameter 'Scene': the steps mode needs a scene");
    for (const auto& o : settings.scene_overrides) {
      try {
        (void)scene::Override::parse(o);
      } catch (const InputError&) {
        throw InputError(file + ": parameter 'Scene overrides': '" + o + "' is not Path/To/Parameter=value");
      }
    }
    // Configurations: the "Configurations" sublist (a sublist each), else one per solver file.
    if (list->isSublist("Configurations")) {
      const auto& configurations = list->sublist("Configurations");
      for (auto it = configurations.begin(); it != configurations.end(); ++it) {
        const std::string& name = configurations.name(it);
        const std::string path = "Configurations/" + name;
        if (!configurations.isSublist(name)) throw InputError(file + ": parameter '" + path + "': expected a sublist");
        const auto c = ConfigurationSettings::table().parse(params::read_parameters(
            configurations.sublist(name), ConfigurationSettings::table().specs(), file, path));
        if (c.solver.empty()) throw InputError(file + ": parameter '" + path + "/Solver': give a solver file");
        settings.configurations.push_back({name, relative_to(file, c.solver), c.newton});
      }
    } else {
      for (const auto& s : settings.solvers) {
        const std::string path = relative_to(file, s);
        settings.configurations.push_back({std::filesystem::path(path).stem().string(), path, {}});
      }
    }
    if (settings.configurations.empty())
      throw InputError(file + ": parameter 'Configurations': give at least one configuration (or Solvers)");
    // Every override is checked now, before any run starts.
    for (const auto& c : settings.configurations) {
      std::vector<scene::Override> overrides;
      for (const auto& o : settings.scene_overrides) overrides.push_back(scene::Override::parse(o));
      for (const auto& o : c.newton) {
        scene::Override newton = scene::Override::parse(o);
        newton.path = "Newton/" + newton.path;
        overrides.push_back(newton);
      }
      (void)scene::read_scene(relative_to(file, settings.scene), overrides);
      (void)linalg::SolverConfiguration::read(c.solver);
    }
    return settings;
  }
  if (!settings.scene.empty() && settings.cell_sizes.empty())
    throw InputError(file + ": parameter 'Cell sizes': give at least one resolution");
  if (settings.solvers.empty()) throw InputError(file + ": parameter 'Solvers': give at least one solver file");
  return settings;
}

int run_study(const StudySettings& settings, const std::string& study_file, const parallel::Communicator& comm,
              std::ostream& log) {
  const std::string& directory = settings.output_directory;
  if (comm.is_root()) std::filesystem::create_directories(directory);
  comm.barrier();
  if (settings.mode == "steps") return study_steps(settings, study_file, comm, log);
  std::vector<linalg::SolverConfiguration> configs;
  for (const auto& s : settings.solvers) configs.push_back(linalg::SolverConfiguration::read(relative_to(study_file, s)));
  Writer writer(directory, comm.is_root(), comm.size());
  if (!settings.scene.empty()) study_scene_systems(settings, study_file, configs, comm, writer, log);
  study_matrix_market(settings, study_file, configs, comm, writer, log);
  return writer.rows();
}

}  // namespace viscompm::study
