#include "viscompm/io/checkpoint.hpp"

#include <filesystem>
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

std::string write_checkpoint(const std::string& directory, const RunState& state, const particles::ParticleSet& particles,
                             const materials::MaterialList& materials, const parallel::Communicator& comm) {
  FileAttributes attributes;
  attributes.reals["time"] = state.time;
  attributes.reals["time_step_cap"] = state.time_step_cap;
  attributes.integers["step"] = state.step;
  attributes.integers["frame"] = state.frame;
  attributes.integers["viscompm_checkpoint"] = format_version;
  attributes.strings["scene"] = state.scene;
  if (!state.decomposition_boxes.empty()) attributes.real_arrays["decomposition_boxes"] = state.decomposition_boxes;
  if (!state.emitter_layers.empty()) attributes.real_arrays["emitter_layers"] = state.emitter_layers;
  const std::string path = (std::filesystem::path(directory) / checkpoint_file_name(state.frame)).string();
  write_particle_file(path, attributes, particles, {}, material_names(materials), comm);
  return path;
}

particles::ParticleSet read_checkpoint(const std::string& path, const parallel::Communicator& comm, RunState& state,
                                       std::string& names) {
  FileAttributes attributes;
  particles::ParticleSet particles = read_particle_file(path, comm, attributes);
  if (attributes.integers.count("viscompm_checkpoint") == 0 || attributes.reals.count("time_step_cap") == 0)
    throw InputError(path + ": not a viscompm checkpoint (a frame file cannot be restarted from)");
  if (attributes.integers.at("viscompm_checkpoint") != format_version)
    throw InputError(path + ": checkpoint format " + std::to_string(attributes.integers.at("viscompm_checkpoint")) +
                     " is not the supported " + std::to_string(format_version));
  state.time = attributes.reals.at("time");
  state.time_step_cap = attributes.reals.at("time_step_cap");
  state.step = attributes.integers.at("step");
  state.frame = static_cast<int>(attributes.integers.at("frame"));
  state.scene = attributes.strings.count("scene") ? attributes.strings.at("scene") : "";
  names = attributes.strings.count("material_names") ? attributes.strings.at("material_names") : "";
  if (attributes.real_arrays.count("decomposition_boxes"))
    state.decomposition_boxes = attributes.real_arrays.at("decomposition_boxes");
  if (attributes.real_arrays.count("emitter_layers")) state.emitter_layers = attributes.real_arrays.at("emitter_layers");
  return particles;
}

}  // namespace viscompm::io
