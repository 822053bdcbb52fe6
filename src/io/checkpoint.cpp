#include "viscompm/io/checkpoint.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <type_traits>
#include <iomanip>
#include <sstream>

#include "viscompm/core/error.hpp"
#include "viscompm/io/frame_writer.hpp"
#include "viscompm/io/particle_file.hpp"

namespace viscompm::io {

namespace {
constexpr std::int64_t format_version = 1;
}

std::string checkpoint_file_name(int frame) {
  std::ostringstream name;
  name << "checkpoint_" << std::setw(5) << std::setfill('0') << frame << ".h5";
  return name.str();
}

std::string step_checkpoint_file_name(std::int64_t step) {
  std::ostringstream name;
  name << "checkpoint_step_" << std::setw(8) << std::setfill('0') << step << ".h5";
  return name.str();
}

void write_checkpoint(const std::string& path, const RunState& state, const particles::ParticleSet& particles,
                      const materials::MaterialList& materials, const parallel::Communicator& comm) {
  FileAttributes attributes;
  attributes.reals["time"] = state.time;
  attributes.reals["time_step_cap"] = state.time_step_cap;
  attributes.reals["balanced_imbalance"] = state.balanced_imbalance;
  attributes.integers["step"] = state.step;
  attributes.integers["frame"] = state.frame;
  attributes.integers["viscompm_checkpoint"] = format_version;
  attributes.strings["scene"] = state.scene;
  if (!state.decomposition_boxes.empty()) attributes.real_arrays["decomposition_boxes"] = state.decomposition_boxes;
  if (!state.emitter_layers.empty()) attributes.real_arrays["emitter_layers"] = state.emitter_layers;
  write_particle_file(path, attributes, particles, {}, material_names(materials), comm);
}

namespace {
// Why the particles read from a checkpoint cannot be this rank's share of a run, or "".
std::string particle_problem(const particles::ParticleSet& particles, std::size_t material_count) {
  std::string problem;
  particles.for_each_field([&](const char* name, const auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    if constexpr (std::is_same_v<T, Vec3> || std::is_same_v<T, Mat3>) {
      for (const auto& value : field)
        if (problem.empty() && !value.allFinite()) problem = std::string("non-finite values in /particles/") + name;
    } else if constexpr (std::is_same_v<T, double>) {
      for (double value : field)
        if (problem.empty() && !std::isfinite(value)) problem = std::string("non-finite values in /particles/") + name;
    }
  });
  for (std::size_t p = 0; p < particles.size() && problem.empty(); ++p) {
    if (particles.material_id[p] < 0 || static_cast<std::size_t>(particles.material_id[p]) >= material_count)
      problem = "material id " + std::to_string(particles.material_id[p]) + " names no material of the checkpoint";
    else if (!(particles.mass[p] > 0.0 && particles.volume0[p] > 0.0))
      problem = "a particle without positive mass and volume";
  }
  return problem;
}
}  // namespace

particles::ParticleSet read_checkpoint(const std::string& path, const parallel::Communicator& comm, RunState& state,
                                       std::string& names) {
  FileAttributes attributes;
  particles::ParticleSet particles = read_particle_file(path, comm, attributes);
  if (attributes.integers.count("viscompm_checkpoint") == 0 || attributes.reals.count("time_step_cap") == 0)
    throw InputError(path + ": not a viscompm checkpoint (a frame file cannot be restarted from)");
  if (attributes.integers.at("viscompm_checkpoint") != format_version)
    throw InputError(path + ": checkpoint format " + std::to_string(attributes.integers.at("viscompm_checkpoint")) +
                     " is not the supported " + std::to_string(format_version));
  if (attributes.reals.count("time") == 0 || attributes.integers.count("step") == 0 ||
      attributes.integers.count("frame") == 0)
    throw InputError(path + ": not a viscompm checkpoint (no time, step or frame)");
  state.time = attributes.reals.at("time");
  state.time_step_cap = attributes.reals.at("time_step_cap");
  state.step = attributes.integers.at("step");
  state.frame = static_cast<int>(attributes.integers.at("frame"));
  state.scene = attributes.strings.count("scene") ? attributes.strings.at("scene") : "";
  if (attributes.reals.count("balanced_imbalance")) state.balanced_imbalance = attributes.reals.at("balanced_imbalance");
  names = attributes.strings.count("material_names") ? attributes.strings.at("material_names") : "";
  if (attributes.real_arrays.count("decomposition_boxes"))
    state.decomposition_boxes = attributes.real_arrays.at("decomposition_boxes");
  if (attributes.real_arrays.count("emitter_layers")) state.emitter_layers = attributes.real_arrays.at("emitter_layers");
  for (double b : state.decomposition_boxes)
    if (!std::isfinite(b)) throw InputError(path + ": non-finite values in /decomposition_boxes");
  if (!(std::isfinite(state.time) && state.time >= 0.0 && std::isfinite(state.time_step_cap) &&
        state.time_step_cap > 0.0 && state.step >= 0 && state.frame >= 0 && std::isfinite(state.balanced_imbalance)))
    throw InputError(path + ": its time, step, frame or time-step cap cannot be those of a run");
  const std::size_t material_count = names.empty() ? 0 : 1 + std::count(names.begin(), names.end(), ',');
  const std::string problem = particle_problem(particles, material_count);
  if (comm.any(!problem.empty()))
    throw InputError(path + ": " + (problem.empty() ? std::string("invalid particle values (on another rank)") : problem));
  return particles;
}

}  // namespace viscompm::io
