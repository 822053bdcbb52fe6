// Scene and solver files are validated on read: an unknown or misspelled parameter, a wrong type
// or an out-of-range value is one line naming the file and the parameter path.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <tuple>
#include <fstream>
#include <optional>
#include <sstream>

#include "viscompm/core/error.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/materials/registry.hpp"
#include "viscompm/scene/command_line.hpp"
#include "viscompm/scene/scene.hpp"

using namespace viscompm;

namespace {
const std::string inputs = VISCOMPM_SOURCE_DIR "/inputs";
const std::string default_scene = inputs + "/scenes/shooting_sponge.xml";

std::string read_text(const std::string& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The default scene with `from` replaced by `to`, written to the temporary directory (its solver
// file made absolute, so that it still resolves).
std::string variant(const std::string& from, const std::string& to) {
  std::string text = read_text(default_scene);
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  const std::string relative_solver = "value=\"../solvers/";
  if (const auto solver = text.find(relative_solver); solver != std::string::npos)
    text.replace(solver, relative_solver.size(), "value=\"" + inputs + "/solvers/");
  const std::string file = std::filesystem::temp_directory_path() / ("viscompm_scene_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(file) << text;
  return file;
}

// The message of the InputError that reading `file` raises.
std::string read_error(const std::string& file, const std::vector<scene::Override>& overrides = {}) {
  try {
    scene::read_scene(file, overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_one_line_naming(const std::string& message, const std::string& file, const std::string& parameter) {
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind(file, 0), 0u) << message;
  EXPECT_NE(message.find("'" + parameter + "'"), std::string::npos) << message;
}
}  // namespace

TEST(Scene, ReadsTheDefaultScene) {
  const auto s = scene::read_scene(default_scene);
  EXPECT_EQ(s.name, "shooting_sponge");
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].model, "oldroyd_b");
  EXPECT_EQ(s.materials[0].values.real("Shear modulus"), 360.0);
  EXPECT_EQ(s.materials[0].values.real("Lame lambda"), 1400.0);
  EXPECT_EQ(s.materials[0].values.real("Weissenberg number"), 50.0);
  EXPECT_EQ(s.bodies.size(), 1u);
  EXPECT_EQ(s.colliders.size(), 3u);
  EXPECT_EQ(s.grid.cell_size, 0.03);
  EXPECT_TRUE(std::filesystem::exists(s.solver_file)) << s.solver_file;
  // Missing parameters take their declared defaults.
  EXPECT_EQ(s.newton.armijo, 1e-4);
}

TEST(Scene, UnknownParameterNamesTheFileThePathAndTheNearestName) {
  const std::string file = variant("name=\"Shear modulus\"", "name=\"Shear modulos\"");
  const std::string message = read_error(file);
  expect_one_line_naming(message, file, "Materials/sponge/Shear modulos");
  EXPECT_NE(message.find("did you mean 'Shear modulus'"), std::string::npos) << message;
}

TEST(Scene, WrongTypeIsRejected) {
  const std::string file = variant("name=\"Frames\" type=\"int\" value=\"18\"", "name=\"Frames\" type=\"string\" value=\"many\"");
  const std::string message = read_error(file);
  expect_one_line_naming(message, file, "Simulation/Frames");
  EXPECT_NE(message.find("expected type int"), std::string::npos) << message;
}

TEST(Scene, OutOfRangeValueIsRejected) {
  const std::string file = variant("name=\"Weissenberg number\" type=\"double\" value=\"50\"",
                                   "name=\"Weissenberg number\" type=\"double\" value=\"-1\"");
  const std::string message = read_error(file);
  expect_one_line_naming(message, file, "Materials/sponge/Weissenberg number");
  EXPECT_NE(message.find("out of range (0, inf]"), std::string::npos) << message;
}

TEST(Scene, UnknownSectionAndUnknownModelAreRejected) {
  std::string file = variant("<ParameterList name=\"Grid\">", "<ParameterList name=\"Gird\">");
  expect_one_line_naming(read_error(file), file, "Gird");
  file = variant("value=\"oldroyd_b\"", "value=\"oldroid_b\"");
  expect_one_line_naming(read_error(file), file, "Materials/sponge/Model");
  file = variant("name=\"Material\" type=\"string\" value=\"sponge\"", "name=\"Material\" type=\"string\" value=\"foam\"");
  expect_one_line_naming(read_error(file), file, "Bodies/sponge/Material");
}

TEST(Scene, EveryModelValidatesItsParametersNamingTheMaterialAndTheParameter) {
  // One out-of-range value per model: exit code 2 with "FILE: parameter 'Materials/<name>/<param>'".
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"oldroyd_b", "Weissenberg number", "0"},      {"oldroyd_b", "Strain update", "implicit"},
      {"oldroyd_b", "Shear modulus", "-1"},          {"herschel_bulkley", "Flow index", "0"},
      {"herschel_bulkley", "Plastic viscosity", "0"}, {"herschel_bulkley", "Yield stress", "-0.1"},
      {"bingham", "Yield stress", "-1"},             {"neo_hookean", "Density", "0"},
      {"svd_plasticity", "Critical compression", "1"}, {"svd_plasticity", "Critical stretch", "0"},
      {"von_mises", "Yield stress", "0"},            {"von_mises", "Hardening modulus", "-5"},
      {"oldroyd_b", "Viscous strain", "volumetric"}, {"herschel_bulkley", "Viscous strain", "dev"}};
  // The default scene with its material replaced by one of `model` with default parameters.
  auto with_model = [](const std::string& model) {
    const std::string text = read_text(default_scene);
    const auto begin = text.find("<ParameterList name=\"Materials\">");
    const auto end = text.find("<ParameterList name=\"Bodies\">");
    return variant(text.substr(begin, end - begin),
                   "<ParameterList name=\"Materials\"><ParameterList name=\"sponge\"><Parameter name=\"Model\" "
                   "type=\"string\" value=\"" + model + "\"/></ParameterList></ParameterList>\n  ");
  };
  for (const auto& [model, parameter, value] : cases) {
    const std::string file = with_model(model);
    EXPECT_NO_THROW(scene::read_scene(file)) << model << " with its defaults";
    const std::string message = read_error(file, {{"Materials/sponge/" + parameter, value}});
    expect_one_line_naming(message, file, "Materials/sponge/" + parameter);
  }
  // A parameter of another model is unknown to this one.
  const std::string file = variant("value=\"oldroyd_b\"/>", "value=\"neo_hookean\"/>");
  expect_one_line_naming(read_error(file), file, "Materials/sponge/Newtonian viscosity");
}

TEST(Scene, CrossParameterCheckRejectsANegativeBulkModulus) {
  // λ may be negative (an auxetic foam), but λ + 2μ/3 must stay positive.
  EXPECT_NO_THROW(scene::read_scene(default_scene, {{"Materials/sponge/Lame lambda", "-200"}}));
  const std::string message = read_error(default_scene, {{"Materials/sponge/Lame lambda", "-240"}});
  expect_one_line_naming(message, default_scene, "Materials/sponge/Lame lambda");
  EXPECT_NE(message.find("bulk modulus"), std::string::npos) << message;
}

TEST(Scene, EverySceneFileParsesAndEveryModelHasAScene) {
  std::set<std::string> models_in_scenes;
  int scenes = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(inputs + "/scenes")) {
    if (entry.path().extension() != ".xml") continue;
    ++scenes;
    scene::SceneConfig s;
    EXPECT_NO_THROW(s = scene::read_scene(entry.path().string())) << entry.path();
    // Its own solver file, or the built-in default (no Solver section).
    EXPECT_TRUE(s.solver_file.empty() || std::filesystem::exists(s.solver_file)) << entry.path();
    EXPECT_NO_THROW(scene::solver_configuration(s)) << entry.path();
    for (const auto& m : s.materials) models_in_scenes.insert(m.model);
    // Each scene can be built: its materials from the registry.
    for (const auto& m : s.materials) EXPECT_NO_THROW(materials::find_model(m.model)->create(m.name, m.values));
  }
  EXPECT_GE(scenes, 14);  // the model scenes and the paper's (inputs/scenes/paper/)
  for (const auto& model : materials::model_names())
    EXPECT_TRUE(models_in_scenes.count(model)) << "no scene in inputs/scenes uses " << model;
}

TEST(Scene, WithoutASolverSectionTheBuiltInDefaultSolverIsUsedWhereverTheSceneLives) {
  // The default scene without its Solver section, in a folder with no solvers/ beside it.
  std::string text = read_text(default_scene);
  const auto begin = text.find("<ParameterList name=\"Solver\">");
  const auto end = text.find("</ParameterList>", begin) + std::string("</ParameterList>").size();
  text.erase(begin, end - begin);
  const auto folder = std::filesystem::temp_directory_path() / ("viscompm_no_solver_" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder / "deeper");
  const std::string file = (folder / "deeper" / "scene.xml").string();
  std::ofstream(file) << text;
  const auto s = scene::read_scene(file);
  EXPECT_TRUE(s.solver_file.empty());
  const auto built_in = scene::solver_configuration(s);
  const auto shipped = linalg::SolverConfiguration::read(inputs + "/solvers/jacobi_cg.xml");
  EXPECT_EQ(built_in.label(), shipped.label());
  EXPECT_NE(built_in.origin().find("built-in"), std::string::npos) << built_in.origin();
  // A Solver/File given is still resolved against the scene and must exist.
  expect_one_line_naming(read_error(file, {{"Solver/File", "../solvers/jacobi_cg.xml"}}), file, "Solver/File");
  std::filesystem::remove_all(folder);
}

TEST(Scene, MissingFileAndMalformedXmlAreInputErrors) {
  EXPECT_NE(read_error("/nonexistent/scene.xml").find("cannot open"), std::string::npos);
  const std::string file = variant("</ParameterList>\n</ParameterList>", "</ParameterList>");
  EXPECT_NE(read_error(file).find("not a valid XML"), std::string::npos);
}

TEST(Scene, SetOverridesOneParameterByPath) {
  const auto s = scene::read_scene(default_scene, {{"Materials/sponge/Weissenberg number", "7"},
                                                   {"Simulation/Gravity", "{0, 0, -1}"},
                                                   {"Newton/Hessian projection", "always"},
                                                   {"Colliders/bullet/Radius", "0.1"}});
  EXPECT_EQ(s.materials[0].values.real("Weissenberg number"), 7.0);
  EXPECT_EQ(s.simulation.gravity, Vec3(0, 0, -1));
  EXPECT_EQ(s.newton.hessian_projection, newton::HessianProjection::always);
  EXPECT_EQ(s.colliders[2].radius, 0.1);
}

TEST(Scene, BadOverridesAreInputErrors) {
  expect_one_line_naming(read_error(default_scene, {{"Simulation/Framez", "3"}}), default_scene, "Simulation/Framez");
  EXPECT_NE(read_error(default_scene, {{"Simulation/Frames", "three"}}).find("cannot read 'three' as int"),
            std::string::npos);
  // Values set by --set are validated like values in the file.
  expect_one_line_naming(read_error(default_scene, {{"Grid/Cell size", "-0.1"}}), default_scene, "Grid/Cell size");
}

TEST(CommandLine, AcceptsTheContractForms) {
  const char* argv[] = {"viscompm", "scene.xml", "--output", "out", "--frames=3", "--set", "A/B=1",
                        "--set=C/D=2", "--solver", "s.xml"};
  const auto cl = scene::parse_command_line(10, argv, scene::ProgramOptions{"viscompm", "test"});
  EXPECT_EQ(cl.input_file, "scene.xml");
  ASSERT_EQ(cl.overrides.size(), 5u);
  EXPECT_EQ(cl.overrides[0].path, "A/B");
  EXPECT_EQ(cl.overrides[1].value, "2");
  EXPECT_EQ(cl.overrides[2].path, "Output/Directory");
  EXPECT_EQ(cl.overrides[3].path, "Simulation/Frames");
  EXPECT_EQ(cl.overrides[4].path, "Solver/File");
  EXPECT_EQ(cl.overrides[4].value, (std::filesystem::current_path() / "s.xml").string());
  const char* bad[] = {"viscompm", "scene.xml", "--bogus=1"};
  EXPECT_THROW(scene::parse_command_line(3, bad, scene::ProgramOptions{"viscompm", "test"}), InputError);
  const char* none[] = {"viscompm"};
  EXPECT_THROW(scene::parse_command_line(1, none, scene::ProgramOptions{"viscompm", "test"}), InputError);
}

// Issue 17, class 6: an option given twice, or a parameter set twice, would silently keep the
// last; a --frames that is not a number is reported as --frames.
TEST(CommandLine, RepeatedOptionsAndParametersSetTwiceAreRejected) {
  auto error = [](std::vector<const char*> argv) {
    try {
      scene::parse_command_line(static_cast<int>(argv.size()), argv.data(), scene::ProgramOptions{"viscompm", "test"});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::string m = error({"viscompm", "scene.xml", "--solver", "a.xml", "--solver=b.xml"});
  EXPECT_NE(m.find("--solver is given more than once"), std::string::npos) << m;
  for (const char* option : {"--output", "--frames", "--restart"}) {
    m = error({"viscompm", "scene.xml", option, "1", option, "2"});
    EXPECT_NE(m.find(std::string(option) + " is given more than once"), std::string::npos) << m;
  }
  m = error({"viscompm", "scene.xml", "--set", "Grid/Cell size=0.1", "--set", "Grid/Cell size=0.2"});
  EXPECT_NE(m.find("'Grid/Cell size' is set twice (--set and --set)"), std::string::npos) << m;
  m = error({"viscompm", "scene.xml", "--frames", "2", "--set", "Simulation/Frames=3"});
  EXPECT_NE(m.find("'Simulation/Frames' is set twice (--set and --frames)"), std::string::npos) << m;
  for (const char* frames : {"abc", "-1", "2x", "", "99999999999"}) {
    m = error({"viscompm", "scene.xml", "--frames", frames});
    EXPECT_NE(m.find("option --frames: '" + std::string(frames) + "' is not a number of frames"), std::string::npos) << m;
    EXPECT_EQ(m.find("Simulation/Frames"), std::string::npos) << m;
  }
  EXPECT_EQ(error({"viscompm", "scene.xml", "--set", "A/B=1", "--set", "C/D=2", "--frames", "0"}), "");
}

// Issue 24: values in their declared ranges that ended a run at its first step (exit 3, naming no
// parameter) are bad input when the scene is read, naming the parameter: a gravity no Min time
// step can follow (beyond CFL·Δx/Δt_min²), a stiffness whose step Hessian holds no inertia in
// double precision ((λ+2μ)Δt_min²/(ρΔx²) > 1/ε), a density below any material's.
TEST(Scene, PhysicalBoundsNameTheParameter) {
  for (const auto& [path, value, reason] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"Simulation/Gravity", "{0, -1e300, 0}", "no step can be taken"},
           {"Materials/sponge/Lame lambda", "1e300", "more than double precision holds"},
           {"Materials/sponge/Shear modulus", "1e300", "more than double precision holds"},
           {"Materials/sponge/Density", "1e-300", "out of range"},
           {"Materials/sponge/Newtonian viscosity", "1e300", "more than double precision holds"}}) {
    const std::string message = read_error(default_scene, {{path, value}});
    expect_one_line_naming(message, default_scene, path);
    EXPECT_NE(message.find(reason), std::string::npos) << message;
  }
  // The bounds at their edges (Cell size 0.03, Min time step 1e-7, CFL 0.6, density 1).
  EXPECT_EQ(read_error(default_scene, {{"Simulation/Gravity", "{0, -1.7e12, 0}"}}), "");
  EXPECT_NE(read_error(default_scene, {{"Simulation/Gravity", "{0, -1.9e12, 0}"}}), "");
  EXPECT_EQ(read_error(default_scene, {{"Materials/sponge/Lame lambda", "4e26"}}), "");
  EXPECT_NE(read_error(default_scene, {{"Materials/sponge/Lame lambda", "5e26"}}), "");
  // The viscous diffusion number η·Δt_min/(ρ·Δx²) at 1/ε = 4.5e15: the default scene's paper
  // convention (η = μ^N/Δt) bounds μ^N at 4.05e12 Pa whatever Δt, the physical one η at 4.05e19 Pa·s.
  EXPECT_EQ(read_error(default_scene, {{"Materials/sponge/Newtonian viscosity", "4e12"}}), "");
  EXPECT_NE(read_error(default_scene, {{"Materials/sponge/Newtonian viscosity", "5e12"}}), "");
  const std::string physical = "Materials/sponge/Viscosity convention";
  EXPECT_EQ(read_error(default_scene, {{physical, "physical"}, {"Materials/sponge/Newtonian viscosity", "4e19"}}), "");
  const std::string too_viscous =
      read_error(default_scene, {{physical, "physical"}, {"Materials/sponge/Newtonian viscosity", "5e19"}});
  expect_one_line_naming(too_viscous, default_scene, "Materials/sponge/Newtonian viscosity");
  // A bound that follows Simulation/Min time step: ten times larger steps, a tenth of the viscosity.
  EXPECT_NE(read_error(default_scene, {{physical, "physical"}, {"Materials/sponge/Newtonian viscosity", "5e18"},
                                       {"Simulation/Min time step", "1e-6"}}),
            "");
  // Physical extremes still read: steel's stiffness, 100 g, a light foam, glass near its
  // transition (1e12 Pa·s, physical convention).
  EXPECT_EQ(read_error(default_scene, {{physical, "physical"}, {"Materials/sponge/Newtonian viscosity", "1e12"}}), "");
  EXPECT_EQ(read_error(default_scene, {{"Materials/sponge/Lame lambda", "1e11"}, {"Simulation/Gravity", "{0, -981, 0}"},
                                       {"Materials/sponge/Density", "0.01"}}),
            "");
}

// --restart is an optional value, not an empty-string switch: absent is no restart, given empty is
// bad input (it used to mean "no restart").
TEST(CommandLine, RestartIsGivenOrNot) {
  const scene::ProgramOptions options{"viscompm", "test"};
  const char* plain[] = {"viscompm", "scene.xml"};
  EXPECT_FALSE(scene::parse_command_line(2, plain, options).restart_file.has_value());
  const char* restart[] = {"viscompm", "scene.xml", "--restart", "c.h5"};
  EXPECT_EQ(scene::parse_command_line(4, restart, options).restart_file, std::optional<std::string>("c.h5"));
  const char* empty[] = {"viscompm", "scene.xml", "--restart="};
  try {
    scene::parse_command_line(3, empty, options);
    ADD_FAILURE() << "--restart= was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "command line: option --restart: needs a checkpoint file");
  }
}

TEST(Scene, AMissingSolverFileNamesTheSceneAndTheParameter) {
  const std::string message = read_error(default_scene, {{"Solver/File", "../solvers/no_such_solver.xml"}});
  expect_one_line_naming(message, default_scene, "Solver/File");
  EXPECT_NE(message.find("no_such_solver.xml"), std::string::npos) << message;
}

TEST(Scene, ValuesTeuchosCannotReadOrWouldMisreadNameTheParameter) {
  // Teuchos would read "none" as 0 and fails on "3" as an array with a dump of its internals.
  for (const auto& [from, to, parameter] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"\"Cell size\" type=\"double\" value=\"0.03\"", "\"Cell size\" type=\"double\" value=\"none\"", "Grid/Cell size"},
           {"\"Gravity\" type=\"Array(double)\" value=\"{0, -9.81, 0}\"", "\"Gravity\" type=\"Array(double)\" value=\"3\"",
            "Simulation/Gravity"},
           {"\"Gravity\" type=\"Array(double)\" value=\"{0, -9.81, 0}\"",
            "\"Gravity\" type=\"Array(double)\" value=\"{0, g, 0}\"", "Simulation/Gravity"},
           {"\"Particles per cell\" type=\"int\" value=\"2\"", "\"Particles per cell\" type=\"bool\" value=\"2x\"",
            "Bodies/sponge/Particles per cell"}}) {
    const std::string file = variant(from, to);
    const std::string message = read_error(file);
    expect_one_line_naming(message, file, parameter);
    EXPECT_NE(message.find("is not a valid"), std::string::npos) << message;
  }
  // The model's name of another type (found by fuzzing: it was an internal error).
  const std::string model = variant("<Parameter name=\"Model\" type=\"string\" value=\"oldroyd_b\"/>",
                                    "<Parameter name=\"Model\" type=\"Array(double)\" value=\"{1, 2, 3}\"/>");
  expect_one_line_naming(read_error(model), model, "Materials/sponge/Model");
  const std::string cut = variant("</ParameterList>", "");
  EXPECT_NE(read_error(cut).find("not a valid XML file (XML parse error at line"), std::string::npos) << read_error(cut);
}

TEST(Scene, AGridTooFineToNumberFailsAtRead) {
  const std::string message = read_error(default_scene, {{"Grid/Cell size", "1e-9"}});
  expect_one_line_naming(message, default_scene, "Grid/Cell size");
  EXPECT_NE(message.find("grid nodes"), std::string::npos) << message;
}

TEST(Scene, NonFiniteValuesSaySo) {
  for (const char* value : {"inf", "-inf", "nan", "1e400"}) {
    const std::string message = read_error(default_scene, {{"Materials/sponge/Weissenberg number", value}});
    expect_one_line_naming(message, default_scene, "Materials/sponge/Weissenberg number");
    EXPECT_NE(message.find("is not a finite number"), std::string::npos) << message;
  }
  const std::string file = variant("<Parameter name=\"Cell size\" type=\"double\" value=\"0.03\"/>",
                                   "<Parameter name=\"Cell size\" type=\"double\" value=\"inf\"/>");
  const std::string message = read_error(file);
  expect_one_line_naming(message, file, "Grid/Cell size");
  EXPECT_NE(message.find("is not a finite number"), std::string::npos) << message;
  expect_one_line_naming(read_error(default_scene, {{"Simulation/Gravity", "{0, nan, 0}"}}), default_scene,
                         "Simulation/Gravity");
}

TEST(SolverConfiguration, ValidatesBelosAndIfpack2Parameters) {
  EXPECT_NO_THROW(linalg::SolverConfiguration::read(inputs + "/solvers/jacobi_cg.xml"));
  auto error = [](const std::string& xml) {
    try {
      linalg::SolverConfiguration::from_xml(xml, "solver.xml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string belos = error(
      "<ParameterList name=\"s\"><ParameterList name=\"Krylov parameters\">"
      "<Parameter name=\"Convergence Tolerence\" type=\"double\" value=\"1e-6\"/></ParameterList></ParameterList>");
  expect_one_line_naming(belos, "solver.xml", "Krylov parameters/Convergence Tolerence");
  EXPECT_NE(belos.find("did you mean 'Convergence Tolerance'"), std::string::npos) << belos;
  const std::string ifpack2 = error(
      "<ParameterList name=\"s\"><ParameterList name=\"Preconditioner parameters\">"
      "<Parameter name=\"relaxation: typo\" type=\"string\" value=\"Jacobi\"/></ParameterList></ParameterList>");
  expect_one_line_naming(ifpack2, "solver.xml", "Preconditioner parameters/relaxation: typo");
  expect_one_line_naming(error("<ParameterList name=\"s\"><Parameter name=\"Preconditioner\" type=\"string\" "
                               "value=\"AMG\"/></ParameterList>"),
                         "solver.xml", "Preconditioner");
}

TEST(Scene, MotionsEmittersAndRegionsAreValidatedOnRead) {
  const std::string bullet_velocity = "<Parameter name=\"Velocity\" type=\"Array(double)\" value=\"{4, 0, 0}\"/>";
  // Keyframes: 3 numbers per keyframe, increasing times.
  std::string file = variant(bullet_velocity,
                             "<Parameter name=\"Keyframe times\" type=\"Array(double)\" value=\"{0, 0.1}\"/>"
                             "<Parameter name=\"Keyframe positions\" type=\"Array(double)\" value=\"{0, 0, 0, 1, 0}\"/>");
  expect_one_line_naming(read_error(file), file, "Colliders/bullet/Keyframe positions");
  file = variant(bullet_velocity,
                 "<Parameter name=\"Keyframe times\" type=\"Array(double)\" value=\"{0.2, 0.1}\"/>"
                 "<Parameter name=\"Keyframe positions\" type=\"Array(double)\" value=\"{0, 0, 0, 1, 0, 0}\"/>");
  expect_one_line_naming(read_error(file), file, "Colliders/bullet/Keyframe times");
  // Emitters: a known material, a non-zero velocity, a disc nozzle by default.
  const std::string output = "<ParameterList name=\"Output\">";
  auto emitter = [&](const std::string& entries) {
    return variant(output, "<ParameterList name=\"Emitters\"><ParameterList name=\"tap\">" + entries +
                               "</ParameterList></ParameterList>" + output);
  };
  file = emitter("<Parameter name=\"Material\" type=\"string\" value=\"paste\"/>");
  expect_one_line_naming(read_error(file), file, "Emitters/tap/Material");
  file = emitter("<Parameter name=\"Material\" type=\"string\" value=\"sponge\"/>"
                 "<Parameter name=\"Velocity\" type=\"Array(double)\" value=\"{0, 0, 0}\"/>");
  expect_one_line_naming(read_error(file), file, "Emitters/tap/Velocity");
  file = emitter("<Parameter name=\"Material\" type=\"string\" value=\"sponge\"/>"
                 "<Parameter name=\"Mass rate\" type=\"double\" value=\"-1\"/>");
  expect_one_line_naming(read_error(file), file, "Emitters/tap/Mass rate");
  file = emitter("<Parameter name=\"Material\" type=\"string\" value=\"sponge\"/>"
                 "<Parameter name=\"Center\" type=\"Array(double)\" value=\"{0.6, 1.0, 0.36}\"/>"
                 "<Parameter name=\"Velocity\" type=\"Array(double)\" value=\"{0, -1, 0}\"/>");
  const auto s = scene::read_scene(file);
  ASSERT_EQ(s.emitters.size(), 1u);
  EXPECT_EQ(s.emitters[0].shape, scene::ShapeKind::disc);  // a cylinder along the velocity, two cells long
  EXPECT_EQ(scene::shape_of(s.emitters[0]).kind, Shape::Kind::cylinder);
  EXPECT_EQ(s.emitters[0].axis, Vec3(0, -1, 0));
  EXPECT_DOUBLE_EQ(s.emitters[0].length, 2 * s.grid.cell_size);
  // Regions: a known body and material.
  auto region = [&](const std::string& entries) {
    return variant(output, "<ParameterList name=\"Regions\"><ParameterList name=\"core\">" + entries +
                               "</ParameterList></ParameterList>" + output);
  };
  file = region("<Parameter name=\"Body\" type=\"string\" value=\"pie\"/>"
                "<Parameter name=\"Material\" type=\"string\" value=\"sponge\"/>");
  expect_one_line_naming(read_error(file), file, "Regions/core/Body");
  file = region("<Parameter name=\"Body\" type=\"string\" value=\"sponge\"/>"
                "<Parameter name=\"Shape\" type=\"string\" value=\"half_space\"/>"
                "<Parameter name=\"Material\" type=\"string\" value=\"sponge\"/>");
  expect_one_line_naming(read_error(file), file, "Regions/core/Shape");
  // --set reaches the new sections.
  file = emitter("<Parameter name=\"Material\" type=\"string\" value=\"sponge\"/>"
                 "<Parameter name=\"Center\" type=\"Array(double)\" value=\"{0.6, 1.0, 0.36}\"/>");
  EXPECT_EQ(scene::read_scene(file, {{"Emitters/tap/Mass rate", "0.25"}}).emitters[0].mass_rate, 0.25);
}

namespace {
// The InputError message of a solver file whose Preconditioner parameters are `parameters`.
std::string solver_error(const std::string& preconditioner, const std::string& parameters,
                         const std::string& top = "", const std::string& krylov = "") {
  const std::string xml = "<ParameterList name=\"s\"><Parameter name=\"Preconditioner\" type=\"string\" value=\"" +
                          preconditioner + "\"/>" + top + "<ParameterList name=\"Krylov parameters\">" + krylov +
                          "</ParameterList><ParameterList name=\"Preconditioner parameters\">" + parameters +
                          "</ParameterList></ParameterList>";
  try {
    linalg::SolverConfiguration::from_xml(xml, "solver.xml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string parameter(const std::string& name, const std::string& type, const std::string& value) {
  return "<Parameter name=\"" + name + "\" type=\"" + type + "\" value=\"" + value + "\"/>";
}
}  // namespace

TEST(SolverConfiguration, EveryShippedSolverFileIsValid) {
  int files = 0;
  for (const std::string folder : {inputs + "/solvers", std::string(VISCOMPM_SOURCE_DIR "/bench/muelu_variants")})
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
      if (read_text(entry.path().string()).find("\"Preconditioner\"") == std::string::npos) continue;  // a study
      EXPECT_NO_THROW(linalg::SolverConfiguration::read(entry.path().string())) << entry.path();
      ++files;
    }
  EXPECT_GE(files, 12);
}

// The libraries' own lists, validators and factories answer every kind of bad solver file with one
// line naming the file and the parameter, before anything is set up.
TEST(SolverConfiguration, ValidatesMueLuAndIfpack2NamesTypesAndValues) {
  const std::string ifpack2 = parameter("Ifpack2 type", "string", "RELAXATION");
  // Ifpack2: a value its validator rejects, with the closest valid value as a hint.
  std::string m = solver_error("Ifpack2", parameter("relaxation: type", "string", "Jacobbi"), ifpack2);
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/relaxation: type");
  EXPECT_NE(m.find("did you mean 'Jacobi'"), std::string::npos) << m;
  // Ifpack2: a type the factory does not know; a wrong parameter type.
  m = solver_error("Ifpack2", "", parameter("Ifpack2 type", "string", "CHEBYCHEV"));
  expect_one_line_naming(m, "solver.xml", "Ifpack2 type");
  EXPECT_NE(m.find("did you mean 'CHEBYSHEV'"), std::string::npos) << m;
  m = solver_error("Ifpack2", parameter("relaxation: sweeps", "string", "two"), ifpack2);
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/relaxation: sweeps");
  // MueLu: a misspelled name (hint from MueLu's master list), a word where an int belongs, an
  // unknown smoother, a bad value inside the smoother's Ifpack2 list, a value MueLu rejects.
  m = solver_error("MueLu", parameter("smoother: typo", "string", "RELAXATION"));
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/smoother: typo");
  EXPECT_NE(m.find("did you mean 'smoother: type'"), std::string::npos) << m;
  m = solver_error("MueLu", parameter("max levels", "string", "ten"));
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/max levels");
  EXPECT_NE(m.find("expected int, got string"), std::string::npos) << m;
  // 2^31 levels: MueLu's interpreter would loop over them for minutes (found by fuzzing).
  m = solver_error("MueLu", parameter("max levels", "int", "2147483647"));
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/max levels");
  EXPECT_NE(m.find("is more than 31"), std::string::npos) << m;
  // Words MueLu and Ifpack2 check only once they have a matrix (found by fuzzing).
  m = solver_error("MueLu", parameter("verbosity", "string", "3"));
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/verbosity");
  m = solver_error("Ifpack2", parameter("partitioner: type", "string", "linaer"),
                   parameter("Ifpack2 type", "string", "BLOCK_RELAXATION"));
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/partitioner: type");
  EXPECT_NE(m.find("did you mean 'linear'"), std::string::npos) << m;
  m = solver_error("MueLu", parameter("smoother: type", "string", "CHEBYCHEV"));
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/smoother: type");
  EXPECT_NE(m.find("did you mean 'CHEBYSHEV'"), std::string::npos) << m;
  m = solver_error("MueLu", parameter("smoother: type", "string", "RELAXATION") +
                                "<ParameterList name=\"smoother: params\">" +
                                parameter("relaxation: type", "string", "Jacobbi") + "</ParameterList>");
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/smoother: params/relaxation: type");
  m = solver_error("MueLu", parameter("multigrid algorithm", "string", "sa2"));
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/multigrid algorithm");
  m = solver_error("MueLu", parameter("aggregation: type", "string", "uncopled"));
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/aggregation: type");
  m = solver_error("MueLu", parameter("coarse: type", "string", "KLU3"));
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/coarse: type");
  // The coarse solver's inner solver, created by name only at set-up (found by fuzzing).
  m = solver_error("MueLu", parameter("coarse: type", "string", "SCHWARZ") + "<ParameterList name=\"coarse: params\">" +
                                parameter("inner preconditioner name", "string", "1e-300") + "</ParameterList>");
  expect_one_line_naming(m, "solver.xml", "Preconditioner parameters/coarse: params/inner preconditioner name");
  EXPECT_NE(m.find("is not an Ifpack2 preconditioner"), std::string::npos) << m;
  m = solver_error("MueLu", parameter("coarse: type", "string", "SCHWARZ") + "<ParameterList name=\"coarse: params\">" +
                                parameter("inner preconditioner name", "string", "AMESOS2") + "</ParameterList>");
  EXPECT_EQ(m, "") << m;
  // Belos: a tolerance that would never be met, no iterations, a non-finite number.
  m = solver_error("none", "", "", parameter("Convergence Tolerance", "double", "-1e-6"));
  expect_one_line_naming(m, "solver.xml", "Krylov parameters/Convergence Tolerance");
  m = solver_error("none", "", "", parameter("Maximum Iterations", "int", "0"));
  expect_one_line_naming(m, "solver.xml", "Krylov parameters/Maximum Iterations");
  m = solver_error("none", "", "", parameter("Convergence Tolerance", "double", "nan"));
  EXPECT_NE(m.find("is not a finite number"), std::string::npos) << m;
  // Parameters for a preconditioner that takes none.
  expect_one_line_naming(solver_error("none", parameter("relaxation: type", "string", "Jacobi")), "solver.xml",
                         "Preconditioner parameters");
}

// Issue 17, classes 1-4: what reading a scene must answer (exit 2, one line naming the file and
// the parameter) instead of running with a changed value or failing later.
TEST(Scene, NonFiniteOrOverflowingItemsOfListsAreRejectedNotReplaced) {
  const std::string bullet_velocity = "<Parameter name=\"Velocity\" type=\"Array(double)\" value=\"{4, 0, 0}\"/>";
  for (const auto& [entries, parameter] : std::vector<std::pair<std::string, std::string>>{
           {"<Parameter name=\"Angular velocity\" type=\"Array(double)\" value=\"{0, nan, 0}\"/>",
            "Colliders/bullet/Angular velocity"},
           {"<Parameter name=\"Velocity\" type=\"Array(double)\" value=\"{1e400, 0, 0}\"/>", "Colliders/bullet/Velocity"},
           {"<Parameter name=\"Keyframe times\" type=\"Array(double)\" value=\"{0, 0.1}\"/>"
            "<Parameter name=\"Keyframe positions\" type=\"Array(double)\" value=\"{0, 0, 0, inf, 0, 0}\"/>",
            "Colliders/bullet/Keyframe positions"},
           {"<Parameter name=\"Keyframe times\" type=\"Array(double)\" value=\"{0, -inf}\"/>",
            "Colliders/bullet/Keyframe times"}}) {
    const std::string file = variant(bullet_velocity, entries);
    const std::string message = read_error(file);
    expect_one_line_naming(message, file, parameter);
    EXPECT_NE(message.find("is not a finite number"), std::string::npos) << message;
  }
}

namespace {
// An ASCII STL of one closed tetrahedron, its first corner replaced by `corner`.
std::string tetrahedron_stl(const std::string& corner) {
  const std::string v[4] = {corner, "1 0 0", "0 1 0", "0 0 1"};
  const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  std::string text = "solid t\n";
  for (const auto& f : faces) {
    text += "facet normal 0 0 0\nouter loop\n";
    for (int k : f) text += "vertex " + v[k] + "\n";
    text += "endloop\nendfacet\n";
  }
  const std::string file = std::filesystem::temp_directory_path() / ("viscompm_mesh_" + std::to_string(::getpid()) + ".stl");
  std::ofstream(file) << text + "endsolid t\n";
  return file;
}

// The default scene with a mesh collider (or body) of `mesh` and `extra` entries.
std::string with_mesh(const std::string& section, const std::string& mesh, const std::string& extra = "") {
  const std::string entries = "<ParameterList name=\"mesh\"><Parameter name=\"Shape\" type=\"string\" value=\"mesh\"/>"
                              "<Parameter name=\"File\" type=\"string\" value=\"" + mesh + "\"/>"
                              "<Parameter name=\"Scale\" type=\"double\" value=\"0.1\"/>"
                              "<Parameter name=\"Center\" type=\"Array(double)\" value=\"{0.5, 0.5, 0.3}\"/>" +
                              extra + (section == "Bodies" ? "<Parameter name=\"Material\" type=\"string\" value=\"sponge\"/>" : "") +
                              "</ParameterList>";
  const std::string open = "<ParameterList name=\"" + section + "\">";
  return variant(open, open + entries);
}
}  // namespace

TEST(Scene, MeshVerticesMustBeFinite) {
  for (const std::string section : {"Colliders", "Bodies"}) {
    EXPECT_NO_THROW(scene::read_scene(with_mesh(section, tetrahedron_stl("0 0 0")))) << section;
    // One coordinate, or all three (Assimp's merging of identical vertices swallowed such a corner;
    // found by fuzzing).
    for (const char* corner : {"nan 0 0", "nan nan nan", "0 inf 0"}) {
      const std::string file = with_mesh(section, tetrahedron_stl(corner));
      const std::string message = read_error(file);
      expect_one_line_naming(message, file, section + "/mesh/File");
      EXPECT_NE(message.find("is not finite"), std::string::npos) << message;  // not "not closed"
    }
  }
  // Finite in the file, but not once scaled.
  const std::string file = with_mesh("Colliders", tetrahedron_stl("1e300 0 0"), "");
  expect_one_line_naming(read_error(file, {{"Colliders/mesh/Scale", "1e300"}}), file, "Colliders/mesh/File");
}

TEST(Scene, VoxelsMustBeWhatOpenVdbAndTheMemoryCanTake) {
  const std::string mesh = tetrahedron_stl("0 0 0");
  // Below OpenVDB's smallest voxel; a band of about 10^12 voxels (a 10 m tetrahedron at 20 µm).
  for (const auto& [voxel, scale, reason] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"1e-6", "0.1", "smallest OpenVDB takes"}, {"2e-5", "10", "GiB"}}) {
    const std::string file = with_mesh("Colliders", mesh, "<Parameter name=\"Voxel size\" type=\"double\" value=\"" + voxel + "\"/>");
    const std::string message = read_error(file, {{"Colliders/mesh/Scale", scale}});
    expect_one_line_naming(message, file, "Colliders/mesh/Voxel size");
    EXPECT_NE(message.find(reason), std::string::npos) << message;
  }
  const std::string message = read_error(default_scene, {{"Output/Surface voxel size", "1e-7"}});
  expect_one_line_naming(message, default_scene, "Output/Surface voxel size");
}

TEST(Scene, MotionsAtTheirLimitsAreCheckedOnRead) {
  // A collider that stops before it starts (emitters were already checked).
  std::string message = read_error(default_scene, {{"Colliders/bullet/Start time", "2"}, {"Colliders/bullet/Stop time", "1"}});
  expect_one_line_naming(message, default_scene, "Colliders/bullet/Stop time");
  // Speeds whose CFL step is below Min time step: a run could not take a single step.
  for (const auto& [parameter, value] : std::vector<std::pair<std::string, std::string>>{
           {"Colliders/bullet/Angular velocity", "{0, 0, 1e8}"},
           {"Colliders/bullet/Velocity", "{1e7, 0, 0}"},
           {"Colliders/bullet/Surface velocity", "{0, 1e7, 0}"},
           {"Bodies/sponge/Velocity", "{0, 1e7, 0}"},
           {"Bodies/sponge/Angular velocity", "{1e8, 0, 0}"}}) {
    message = read_error(default_scene, {{parameter, value}});
    expect_one_line_naming(message, default_scene, parameter);
    EXPECT_NE(message.find("Min time step"), std::string::npos) << message;
  }
  EXPECT_NO_THROW(scene::read_scene(default_scene, {{"Colliders/bullet/Angular velocity", "{0, 0, 1e3}"}}));
}

TEST(Scene, NozzlesMustLieInsideTheGrid) {
  const std::string output = "<ParameterList name=\"Output\">";
  const std::string file = variant(output, "<ParameterList name=\"Emitters\"><ParameterList name=\"tap\">"
                                           "<Parameter name=\"Material\" type=\"string\" value=\"sponge\"/>"
                                           "<Parameter name=\"Velocity\" type=\"Array(double)\" value=\"{0, -1, 0}\"/>"
                                           "<Parameter name=\"Center\" type=\"Array(double)\" value=\"{0.6, 1.0, 0.36}\"/>"
                                           "</ParameterList></ParameterList>" + output);
  EXPECT_NO_THROW(scene::read_scene(file));
  for (const char* centre : {"{0.6, 1.19, 0.36}", "{0.6, 5, 0.36}", "{0.05, 1.0, 0.36}"})
    expect_one_line_naming(read_error(file, {{"Emitters/tap/Center", centre}}), file, "Emitters/tap/Center");
}
