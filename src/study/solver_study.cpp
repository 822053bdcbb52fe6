#include "viscompm/study/solver_study.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <random>
#include <ostream>
#include <sstream>

#include "viscompm/core/error.hpp"
#include "viscompm/linalg/matrix_market.hpp"
#include "viscompm/scene/parameter_io.hpp"
#include "viscompm/simulation/simulation.hpp"

namespace viscompm::study {

const ParameterTable<StudySettings>& StudySettings::table() {
  static const ParameterTable<StudySettings> t = [] {
    ParameterTable<StudySettings> table;
    using S = StudySettings;
    table.string(&S::scene, "Scene", "", {}, "scene whose Newton systems are studied, relative to this file")
        .real_list(&S::cell_sizes, "Cell sizes", {}, Range::positive(), "resolutions Δx [m], one problem each")
        .real_list(&S::time_steps, "Time steps", {10.0}, Range::positive(), "Δt of the step, in Time step unit")
        .string(&S::time_step_unit, "Time step unit", "elastic CFL", {"elastic CFL", "seconds"},
                "elastic CFL: multiples of Δx/c with c = √((λ+2μ)/ρ) of the stiffest material")
        .real(&S::time, "Time", 0.0, Range::non_negative(), "advance the scene to this time before taking the system [s]")
        .string(&S::right_hand_side, "Right-hand side", "newton", {"newton", "random"},
                "newton: the step's −∇E; random: m_i times uniform(−1, 1) per dof, seeded by node (rank-independent)")
        .string_list(&S::solvers, "Solvers", {}, "solver XML files, relative to this file")
        .string_list(&S::matrix_market_files, "Matrix Market files", {}, "extra problems (X.mtx with optional X_rhs.mtx)")
        .integer(&S::repetitions, "Repetitions", 1, Range::closed(1, 100), "solves per pair; the fastest is kept")
        .string(&S::output_directory, "Output directory", "output/study", {}, "where study.csv and study.png go")
        .boolean(&S::plot, "Plot", true, "write study.png with scripts/plot_study.py (needs python3-matplotlib)");
    return table;
  }();
  return t;
}

namespace {
std::string relative_to(const std::string& file, const std::string& path) {
  const std::filesystem::path p(path);
  return p.is_absolute() ? path : (std::filesystem::path(file).parent_path() / p).lexically_normal().string();
}

std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
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
              "relative_residual,converged\n";
    operators_ << "problem,resolution,dofs,ranks,preconditioner,operator,assembly_seconds,apply_seconds\n";
  }
  void row(const Row& r) {
    ++rows_;
    if (!root_) return;
    study_ << '"' << r.problem << "\"," << r.resolution << ',' << r.dofs << ',' << r.nonzeros << ',' << ranks_ << ",\""
           << r.report.preconditioner << "\"," << r.report.setup_seconds << ',' << r.report.solve_seconds << ','
           << r.report.iterations << ',' << r.report.relative_residual << ',' << (r.report.converged ? 1 : 0) << '\n';
    study_.flush();
  }
  void operator_row(const Row& r, const std::string& form, double assembly, double apply) {
    if (!root_) return;
    operators_ << '"' << r.problem << "\"," << r.resolution << ',' << r.dofs << ',' << ranks_ << ",\""
               << r.report.preconditioner << "\"," << form << ',' << assembly << ',' << apply << '\n';
    operators_.flush();
  }
  int rows() const { return rows_; }

 private:
  bool root_;
  int ranks_;
  int rows_ = 0;
  std::ofstream study_, operators_;
};
}  // namespace

StudySettings read_study(const std::string& file, const std::vector<scene::Override>& overrides) {
  auto list = scene::read_xml_file(file);
  const auto& specs = StudySettings::table().specs();
  for (const auto& o : overrides) {
    const ParameterSpec* spec = nullptr;
    for (const auto& s : specs)
      if (s.name == o.path) spec = &s;
    if (spec == nullptr) throw InputError(file + ": --set '" + o.path + "': unknown parameter");
    scene::set_entry(*list, o.path, scene::parse_value(*spec, o.value));
  }
  StudySettings settings = StudySettings::table().parse(scene::read_parameters(*list, specs, file, ""));
  if (settings.scene.empty() && settings.matrix_market_files.empty())
    throw InputError(file + ": parameter 'Scene': a study needs a scene or Matrix Market files");
  if (!settings.scene.empty() && settings.cell_sizes.empty())
    throw InputError(file + ": parameter 'Cell sizes': give at least one resolution");
  if (settings.solvers.empty()) throw InputError(file + ": parameter 'Solvers': give at least one solver file");
  return settings;
}

int run_study(const StudySettings& settings, const std::string& study_file, const parallel::Communicator& comm,
              std::ostream& log) {
  std::vector<linalg::SolverConfiguration> configs;
  for (const auto& s : settings.solvers) configs.push_back(linalg::SolverConfiguration::read(relative_to(study_file, s)));
  const std::string& directory = settings.output_directory;
  if (comm.is_root()) std::filesystem::create_directories(directory);
  comm.barrier();
  Writer writer(directory, comm.is_root(), comm.size());

  if (!settings.scene.empty()) {
    const scene::SceneConfig base = scene::read_scene(relative_to(study_file, settings.scene));
    for (double h : settings.cell_sizes) {
      scene::SceneConfig scene = base;
      scene.grid.cell_size = h;
      // Advance with the scene's own solver, then take the step's Newton system at several Δt.
      simulation::Simulation sim(scene, linalg::SolverConfiguration::read(scene.solver_file), comm);
      if (settings.time > 0.0) {
        simulation::RunSummary summary;
        sim.advance_to(settings.time, summary);
      }
      double wave_speed = 0.0;
      for (const auto& m : sim.materials()) wave_speed = std::max(wave_speed, m->wave_speed());
      auto& integrator = sim.integrator();
      double largest_step = 0.0;
      for (double step : settings.time_steps) largest_step = std::max(largest_step, step);
      integrator.prepare(sim.particles(), settings.time_step_unit == "elastic CFL" ? largest_step * sim.grid().dx / wave_speed
                                                                               : largest_step);
      for (double step : settings.time_steps) {
        const bool cfl = settings.time_step_unit == "elastic CFL";
        const double dt = cfl ? step * sim.grid().dx / wave_speed : step;
        const auto objective = integrator.build_objective(sim.particles(), sim.time(), dt);
        Row row;
        row.problem = base.name + " t=" + number(sim.time()) + " dt=" + number(step) + (cfl ? "xCFL" : "s");
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
        for (std::size_t i = 0; i < layout.owned_count; ++i) {
          if (settings.right_hand_side != "newton") {
            std::mt19937_64 rng(static_cast<std::uint64_t>(layout.nodes[i]));
            std::uniform_real_distribution<double> u(-1.0, 1.0);
            rhs[i] = integrator.grid_mass()[i] * Vec3(u(rng), u(rng), u(rng));
          }
        }
        for (std::size_t i = 0; i < rhs.size(); ++i) rhs[i] = objective->constraints.projection[i] * rhs[i];
        std::int64_t nonzeros = -1;
        for (const auto& config : configs) {
          linalg::NewtonSystem system(integrator.node_space(), config);
          double assembly = 1e300, apply = 0.0;
          linalg::LinearSolveReport best;
          try {
            for (int k = 0; k < settings.repetitions; ++k) {
              const auto start = std::chrono::steady_clock::now();
              system.assemble(*objective->potential, objective->initial_guess, true);
              assembly = std::min(assembly, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
              NodeVectorField dv;
              const auto report = system.solve(rhs, dv);
              if (k == 0 || report.setup_seconds + report.solve_seconds < best.setup_seconds + best.solve_seconds)
                best = report;
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
          row.dofs = system.global_rows();
          row.nonzeros = nonzeros;
          row.report = best;
          writer.row(row);
          writer.operator_row(row, system.matrix_free() ? "matrix-free" : "assembled", assembly, apply);
          if (comm.is_root())
            log << std::setw(28) << std::left << row.problem << " dx=" << h << " dofs=" << row.dofs << "  "
                << std::setw(22) << best.preconditioner << std::right << " it=" << std::setw(5) << best.iterations
                << " setup=" << std::setprecision(3) << best.setup_seconds << "s solve=" << best.solve_seconds
                << "s" << (best.converged ? "" : "  NOT CONVERGED") << std::setprecision(6) << std::endl;
        }
      }
    }
  }
  for (const auto& file : settings.matrix_market_files) {
    const std::string path = relative_to(study_file, file);
    for (const auto& config : configs) {
      if (config.matrix_free()) continue;  // a matrix-free operator needs the scene's particles
      linalg::MatrixMarketSolve solved;
      try {
        solved = linalg::solve_matrix_market(path, config, comm);
      } catch (const InputError&) {
        throw;
      } catch (const std::exception& e) {
        solved.report.preconditioner = config.label();  // a failed set-up is a row, not a crash
        if (comm.is_root()) log << "  " << config.label() << " failed: " << e.what() << "\n";
      }
      Row row;
      row.problem = std::filesystem::path(path).stem().string();
      row.dofs = solved.rows;
      row.nonzeros = solved.nonzeros;
      row.report = solved.report;
      writer.row(row);
      writer.operator_row(row, "assembled", 0.0, solved.apply_seconds);
      if (comm.is_root())
        log << std::setw(28) << std::left << row.problem << " dofs=" << row.dofs << "  " << std::setw(22)
            << solved.report.preconditioner << std::right << " it=" << std::setw(5) << solved.report.iterations
            << (solved.report.converged ? "" : "  NOT CONVERGED") << std::endl;
    }
  }
  return writer.rows();
}

}  // namespace viscompm::study
