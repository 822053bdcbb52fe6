#include "viscompm/linalg/linear_solver.hpp"

#include <BelosSolverFactory.hpp>
#include <BelosTpetraAdapter.hpp>
#include <Teuchos_XMLParameterListCoreHelpers.hpp>

#include <fstream>

#include "solver_configuration_impl.hpp"
#include "solver_validation.hpp"
#include "viscompm/core/error.hpp"
#include "linalg_types.hpp"
#include "viscompm/params/parameter_io.hpp"

namespace viscompm::linalg {

const ParameterTable<SolverSettings>& SolverSettings::table() {
  static const ParameterTable<SolverSettings> t = [] {
    ParameterTable<SolverSettings> table;
    using S = SolverSettings;
    table.string(&S::label, "Label", "", {}, "name of this configuration in solver.csv and study.csv")
        .choice(&S::operator_form, "Operator", OperatorForm::assembled,
                {{"assembled", OperatorForm::assembled}, {"matrix-free", OperatorForm::matrix_free}},
                "assembled Tpetra matrix, or the paper's matrix-free Hessian-vector product (§5.7)")
        .string(&S::krylov_solver, "Krylov solver", "Pseudo Block CG", {"Pseudo Block CG", "Block CG"},
                "Belos solver (Pseudo Block CG is Belos' CG)")
        .choice(&S::preconditioner, "Preconditioner", PreconditionerKind::ifpack2,
                {{"none", PreconditionerKind::none}, {"Jacobi", PreconditionerKind::jacobi},
                 {"Ifpack2", PreconditionerKind::ifpack2}, {"MueLu", PreconditionerKind::muelu}},
                "none; Jacobi (exact diagonal of H, also matrix-free); Ifpack2 or MueLu (assembled only)")
        .string(&S::ifpack2_type, "Ifpack2 type", "RELAXATION", {}, "Ifpack2::Factory name (RELAXATION, CHEBYSHEV, ...)")
        .choice(&S::prolongation, "Prolongation", Prolongation::algebraic,
                {{"algebraic", Prolongation::algebraic}, {"trilinear", Prolongation::trilinear},
                 {"quadratic B-spline", Prolongation::quadratic_bspline},
                 {"piecewise constant", Prolongation::piecewise_constant}},
                "MueLu: the prolongators of its own aggregation (algebraic), or geometric ones between the grids "
                "Δx, 2Δx, 4Δx, ... (trilinear, the coarse quadratic B-spline at the fine nodes, or piecewise "
                "constant: 2×2×2-node aggregates, unsmoothed)")
        .integer(&S::coarsest_nodes, "Coarsest nodes", 2000, Range::at_least(1),
                 "geometric prolongation: coarsen until a level has at most this many nodes")
        .choice(&S::near_nullspace, "Near nullspace", NearNullspaceModes::rigid_body_modes,
                {{"rigid body modes", NearNullspaceModes::rigid_body_modes},
                 {"translations", NearNullspaceModes::translations}},
                "algebraic MueLu: the modes its aggregates must represent (the 6 rigid-body modes, or the 3 "
                "translations, for aggregates of a node or two)")
        .choice(&S::smoother_blocks, "Smoother blocks", SmootherBlocks::library,
                {{"library", SmootherBlocks::library}, {"grid lines", SmootherBlocks::grid_lines}},
                "library: smoothers as the Preconditioner parameters say; grid lines: the fine level's "
                "BLOCK_RELAXATION smoother (Ifpack2, or MueLu's \"level 0\") gets its blocks from viscompm — the "
                "runs of grid nodes along each axis, overlapping (one per axis), which solve the strong coupling "
                "across thin stiff parts — and its damping (Line damping / λmax)")
        .integer(&S::line_length, "Line length", 16, Range::closed(1, 4096),
                 "grid lines: the most nodes in one block (longer runs are cut into near-equal pieces)")
        .real(&S::line_damping, "Line damping", 1.5, Range::open_closed(0.0, 2.0),
              "grid lines: the block Jacobi damping is this over the largest eigenvalue of (blocks⁻¹ H), "
              "estimated by power iterations at each set-up (< 2 for a convergent smoother)")
        .integer(&S::line_levels, "Line levels", 1, Range::closed(1, 31),
                 "grid lines on a geometric hierarchy: the finest this many levels smooth on the lines of their "
                 "own grid (the coarse levels' smoothers as level 0's, each with its own damping)")
        .choice(&S::cycle, "Cycle", Cycle::muelu, {{"MueLu", Cycle::muelu}, {"lean", Cycle::lean}},
                "MueLu: the hierarchy's V-cycle as MueLu applies it; lean: viscompm applies the fine level (the "
                "grid-line smoother with its own factored blocks, the products with the operator CG uses) and "
                "MueLu the levels below (needs Smoother blocks = grid lines)")
        .integer(&S::fine_sweeps, "Fine sweeps", 1, Range::closed(1, 8),
                 "lean cycle: grid-line smoother sweeps before and after the coarse correction (each sweep past "
                 "the first costs one more product with the operator)")
        .choice(&S::fine_chebyshev, "Fine smoother", false, {{"sweeps", false}, {"Chebyshev", true}},
                "lean cycle: Fine sweeps damped line-smoother sweeps, or the Chebyshev iteration of degree Fine "
                "sweeps on the undamped line blocks (the same products with the operator, a stronger smoothing)")
        .real(&S::fine_chebyshev_ratio, "Fine Chebyshev ratio", 20.0, Range::at_least(1.0),
              "Fine smoother = Chebyshev: the largest eigenvalue of (blocks⁻¹ H) over the smallest it targets")
        .real(&S::fine_chebyshev_boost, "Fine Chebyshev boost", 1.1, Range::closed(1.0, 4.0),
              "Fine smoother = Chebyshev: the power iterations' estimate of that eigenvalue is multiplied by this "
              "(an underestimate would amplify the modes above it)")
        .choice(&S::deflation, "Deflation", Deflation::none,
                {{"none", Deflation::none}, {"stiff bodies", Deflation::stiff_bodies}},
                "stiff bodies: the 6 rigid motions of every stiff body (connected material whose elastic waves "
                "cross Stiff CFL cells or more in a step) are solved exactly beside the preconditioner (balancing "
                "deflation): the softest modes of stiff pieces in soft material, which no grid hierarchy holds")
        .real(&S::stiff_cfl, "Stiff CFL", 30.0, Range::positive(),
              "deflation: a material is stiff where c Δt/Δx reaches this (c its fastest elastic wave)")
        .integer(&S::max_stiff_bodies, "Max stiff bodies", 64, Range::closed(1, 10000),
                 "deflation: the largest this many stiff bodies are deflated (6 columns each)")
        .integer(&S::max_ranks, "Ranks", 0, Range::at_least(0),
                 "the most ranks this configuration runs on (0: any; 1 for preconditioners that only work on "
                 "one rank): a run on more is bad input");
    return table;
  }();
  return t;
}

namespace {
constexpr const char* krylov_sublist = "Krylov parameters";
constexpr const char* block_relaxation = "BLOCK_RELAXATION";

// Ifpack2's (and MueLu's) three spellings of its block relaxation.
bool is_block_relaxation(const std::string& type) {
  return type == block_relaxation || type == "BLOCK RELAXATION" || type == "BLOCKRELAXATION";
}
constexpr const char* preconditioner_sublist = "Preconditioner parameters";

// Smoother blocks = grid lines: the fine level's smoother must be a block relaxation whose blocks
// viscompm can give (partitioner "user"); viscompm sets the blocks and the damping itself. Returns
// how it combines them.
BlockCombination validate_grid_line_smoother(const SolverConfiguration::Impl& impl, const std::string& origin) {
  const SolverSettings& s = impl.settings;
  const Teuchos::ParameterList* smoother = nullptr;
  std::string where;
  if (s.preconditioner == PreconditionerKind::ifpack2 && s.ifpack2_kind == Ifpack2Kind::block_relaxation) {
    smoother = impl.preconditioner_parameters.get();
    where = preconditioner_sublist;
  } else if (s.preconditioner == PreconditionerKind::muelu && impl.preconditioner_parameters->isSublist("level 0")) {
    const Teuchos::ParameterList& level0 = impl.preconditioner_parameters->sublist("level 0");
    if (level0.isType<std::string>("smoother: type") && is_block_relaxation(level0.get<std::string>("smoother: type")) &&
        level0.isSublist("smoother: params")) {
      smoother = &level0.sublist("smoother: params");
      where = std::string(preconditioner_sublist) + "/level 0/smoother: params";
    }
  }
  if (smoother == nullptr)
    throw parameter_error(origin, "Smoother blocks", "grid lines need a BLOCK_RELAXATION smoother on the fine "
                     "level: Ifpack2 type BLOCK_RELAXATION, or MueLu's \"level 0\" list with smoother: type BLOCK "
                     "RELAXATION and its smoother: params");
  for (const char* name : {"partitioner: local parts", "partitioner: map", "partitioner: parts",
                           "relaxation: damping factor"})
    if (smoother->isParameter(name))
      throw parameter_error(origin, where + "/" + name, "set by viscompm when Smoother blocks = grid lines");
  auto word = [smoother](const char* name, const char* otherwise) {
    return smoother->isType<std::string>(name) ? smoother->get<std::string>(name) : std::string(otherwise);
  };
  if (word("partitioner: type", "") != "user")
    throw parameter_error(origin, where + "/partitioner: type", "must be 'user' when Smoother blocks = grid lines");
  const std::string relaxation = word("relaxation: type", "Jacobi");
  if (relaxation == "Jacobi") return BlockCombination::jacobi;
  if (relaxation == "Symmetric Gauss-Seidel") return BlockCombination::symmetric_gauss_seidel;
  throw parameter_error(origin, where + "/relaxation: type", "must be 'Jacobi' or 'Symmetric "
                   "Gauss-Seidel' when Smoother blocks = grid lines (the blocks overlap: their additive or symmetric "
                   "multiplicative combination is symmetric)");
}

std::shared_ptr<SolverConfiguration::Impl> parse(const Teuchos::ParameterList& list, const std::string& origin) {
  auto impl = std::make_shared<SolverConfiguration::Impl>();
  impl->origin = origin;
  const ParameterValues values =
      params::read_parameters(list, SolverSettings::table().specs(), origin, "", {krylov_sublist, preconditioner_sublist});
  impl->settings = SolverSettings::table().parse(values);
  SolverSettings& s = impl->settings;
  if (is_block_relaxation(s.ifpack2_type)) {
    s.ifpack2_type = block_relaxation;
    s.ifpack2_kind = Ifpack2Kind::block_relaxation;
  }

  impl->krylov_parameters = Teuchos::rcp(new Teuchos::ParameterList(
      list.isSublist(krylov_sublist) ? list.sublist(krylov_sublist) : Teuchos::ParameterList()));
  impl->preconditioner_parameters = Teuchos::rcp(new Teuchos::ParameterList(
      list.isSublist(preconditioner_sublist) ? list.sublist(preconditioner_sublist) : Teuchos::ParameterList()));

  // Belos, Ifpack2 and MueLu know their parameters: a misspelled name, a wrong type or a bad value
  // is bad input now rather than a failure (or a hang) once particles are sampled and solved.
  Belos::SolverFactory<scalar_type, multivector_type, operator_type> factory;
  auto solver = factory.create(s.krylov_solver, Teuchos::null);
  validate_krylov_parameters(*impl->krylov_parameters, *solver->getValidParameters(), origin, krylov_sublist);

  const std::string preconditioner_word = values.string("Preconditioner");
  const bool library_preconditioner =
      s.preconditioner == PreconditionerKind::ifpack2 || s.preconditioner == PreconditionerKind::muelu;
  if (s.operator_form == OperatorForm::matrix_free && library_preconditioner)
    throw parameter_error(origin, "Preconditioner", preconditioner_word +
                     " needs the assembled matrix (Operator = assembled)");
  if (s.preconditioner == PreconditionerKind::ifpack2)
    validate_ifpack2_parameters(s.ifpack2_type, *impl->preconditioner_parameters, origin, "Ifpack2 type",
                                preconditioner_sublist);
  if (s.preconditioner == PreconditionerKind::muelu)
    validate_muelu_parameters(*impl->preconditioner_parameters, origin, preconditioner_sublist);
  if (!library_preconditioner && impl->preconditioner_parameters->numParams() > 0)
    throw parameter_error(origin, preconditioner_sublist, preconditioner_word +
                     " takes no parameters");
  if (s.prolongation != Prolongation::algebraic && s.preconditioner != PreconditionerKind::muelu)
    throw parameter_error(origin, "Prolongation", "geometric prolongators are for Preconditioner = MueLu");
  if (s.smoother_blocks == SmootherBlocks::grid_lines) s.line_combination = validate_grid_line_smoother(*impl, origin);
  if (s.cycle == Cycle::lean && (s.preconditioner != PreconditionerKind::muelu || s.smoother_blocks != SmootherBlocks::grid_lines))
    throw parameter_error(origin, "Cycle", "the lean cycle needs Preconditioner = MueLu and Smoother blocks = grid lines");
  if (s.line_levels > 1 && (s.smoother_blocks != SmootherBlocks::grid_lines || s.prolongation == Prolongation::algebraic))
    throw parameter_error(origin, "Line levels", "coarse grid lines need Smoother blocks = grid lines and a geometric "
                                                 "Prolongation (the coarse levels of an algebraic hierarchy are no grids)");
  const Teuchos::ParameterList& preconditioner_list = *impl->preconditioner_parameters;
  s.muelu_reuse = s.preconditioner == PreconditionerKind::muelu && preconditioner_list.isType<std::string>("reuse: type") &&
                  preconditioner_list.get<std::string>("reuse: type") != "none";
  if (s.label.empty()) {
    s.label = (s.operator_form == OperatorForm::matrix_free ? "matrix-free " : "") +
              (s.preconditioner == PreconditionerKind::ifpack2 ? "Ifpack2 " + s.ifpack2_type : preconditioner_word);
    if (impl->preconditioner_parameters->isParameter("relaxation: type"))
      s.label += " " + impl->preconditioner_parameters->get<std::string>("relaxation: type");
  }
  return impl;
}
}  // namespace

namespace {
// A measured choice's file: its candidates and the schedule of its trials.
struct ChoiceFile {
  std::string label;
  StringList candidates;
  int recheck_steps = 16;
  int max_recheck_steps = 256;
  double regime_change = 2.0;
  int regime_steps = 4;
  double trial_overhead = 0.05;

  SolverChoiceSettings schedule() const {
    return {recheck_steps, max_recheck_steps, regime_change, regime_steps, trial_overhead};
  }
  static const ParameterTable<ChoiceFile>& table() {
    static const ParameterTable<ChoiceFile> t = [] {
      ParameterTable<ChoiceFile> table;
      using C = ChoiceFile;
      table.string(&C::label, "Label", "measured choice", {}, "name of this choice in messages")
          .string_list(&C::candidates, "Choose between", {},
                       "solver files (relative to this one) of which the run uses the cheapest per time step, as "
                       "measured; each is tried for one step in this order (the one whose worst case is mildest first)")
          .integer(&C::recheck_steps, "Recheck steps", 16, Range::closed(1, 1000000),
                   "steps of the chosen one before the others are tried again")
          .integer(&C::max_recheck_steps, "Max recheck steps", 256, Range::closed(1, 1000000),
                   "the interval between trials doubles, each time a trial confirms the choice, up to this")
          .real(&C::regime_change, "Regime change", 2.0, Range::open_closed(1.0, 1e6),
                "a trial at once when the chosen one's recent seconds per step move by this factor from its trial's, "
                "or one step does and costs more than the closest loser's trial step")
          .integer(&C::regime_steps, "Regime steps", 4, Range::closed(1, 1000000),
                   "steps after a trial before a regime change is looked for")
          .real(&C::trial_overhead, "Trial overhead", 0.05, Range::open_closed(0.0, 1.0),
                "the next trial waits until the losers' last trial steps, beyond the winner's cost, are at most "
                "this share of the winner's steps in between (capped by Max recheck steps)");
      return table;
    }();
    return t;
  }
};

std::string directory_of(const std::string& file) {
  const auto slash = file.find_last_of('/');
  return slash == std::string::npos ? std::string() : file.substr(0, slash + 1);
}

// A file with `Choose between` is a measured choice; its candidates are read as files of their
// own (each validated as usual; a candidate that is itself a choice is bad input).
std::shared_ptr<SolverConfiguration::Impl> parse_choice(const Teuchos::ParameterList& list, const std::string& origin,
                                                        const std::string& directory) {
  auto impl = std::make_shared<SolverConfiguration::Impl>();
  impl->origin = origin;
  const ChoiceFile file = ChoiceFile::table().parse(params::read_parameters(list, ChoiceFile::table().specs(), origin, ""));
  if (file.candidates.size() < 2)
    throw parameter_error(origin, "Choose between", "a measured choice needs at least two solver files, got " +
                                                        std::to_string(file.candidates.size()));
  if (file.max_recheck_steps < file.recheck_steps)
    throw parameter_error(origin, "Max recheck steps", "is less than Recheck steps (" +
                                                           std::to_string(file.recheck_steps) + ")");
  for (const std::string& name : file.candidates) {
    const std::string path = !name.empty() && name[0] == '/' ? name : directory + name;
    if (!std::ifstream(path))
      throw parameter_error(origin, "Choose between", "cannot open '" + path + "'");
    SolverConfiguration candidate = SolverConfiguration::read(path);
    if (candidate.is_choice())
      throw parameter_error(origin, "Choose between", "'" + name + "' is itself a measured choice");
    impl->candidates.push_back(std::move(candidate));
  }
  impl->choice = file.schedule();
  impl->settings.label = file.label;
  impl->krylov_parameters = Teuchos::rcp(new Teuchos::ParameterList());
  impl->preconditioner_parameters = Teuchos::rcp(new Teuchos::ParameterList());
  return impl;
}

std::shared_ptr<SolverConfiguration::Impl> parse_file(const Teuchos::ParameterList& list, const std::string& origin,
                                                      const std::string& directory) {
  return list.isParameter("Choose between") ? parse_choice(list, origin, directory) : parse(list, origin);
}
}  // namespace

SolverConfiguration SolverConfiguration::read(const std::string& file) {
  SolverConfiguration c;
  c.impl_ = parse_file(*params::read_xml_file(file), file, directory_of(file));
  return c;
}

SolverConfiguration SolverConfiguration::from_xml(const std::string& xml, const std::string& origin) {
  SolverConfiguration c;
  Teuchos::RCP<Teuchos::ParameterList> list;
  try {
    list = Teuchos::getParametersFromXmlString(xml);
  } catch (const std::exception& e) {
    throw InputError(origin + ": not a valid XML parameter list");
  }
  c.impl_ = parse_file(*list, origin, "");
  return c;
}

const std::string& SolverConfiguration::label() const { return impl_->settings.label; }
void SolverConfiguration::check_rank_count(int ranks) const {
  for (const auto& candidate : impl_->candidates) candidate.check_rank_count(ranks);
  const int most = impl_->settings.max_ranks;
  if (most > 0 && ranks > most)
    throw parameter_error(origin(), "Ranks", "this solver file runs on at most " + std::to_string(most) +
                     (most == 1 ? " rank (one rank only)" : " ranks") + ", the run has " + std::to_string(ranks));
}

const std::string& SolverConfiguration::origin() const { return impl_->origin; }
const std::vector<SolverConfiguration>& SolverConfiguration::candidates() const { return impl_->candidates; }
const SolverChoiceSettings& SolverConfiguration::choice() const { return impl_->choice; }
bool SolverConfiguration::matrix_free() const { return impl_->settings.operator_form == OperatorForm::matrix_free; }

}  // namespace viscompm::linalg
