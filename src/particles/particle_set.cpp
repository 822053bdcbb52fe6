#include "viscompm/particles/particle_set.hpp"

#include <cstring>
#include <type_traits>

namespace viscompm::particles {

namespace {
// Number of doubles a value of a field's element type packs into.
template <class T>
constexpr std::size_t doubles_of() {
  if constexpr (std::is_same_v<T, Vec3>) return 3;
  else if constexpr (std::is_same_v<T, Mat3>) return 9;
  else return 1;
}

template <class T>
void pack_value(const T& value, std::vector<double>& buffer) {
  if constexpr (std::is_same_v<T, Vec3> || std::is_same_v<T, Mat3>) {
    buffer.insert(buffer.end(), value.data(), value.data() + doubles_of<T>());
  } else if constexpr (std::is_same_v<T, ParticleId>) {
    double bits;  // ids travel bit-exactly inside a double slot
    static_assert(sizeof(bits) == sizeof(value));
    std::memcpy(&bits, &value, sizeof(bits));
    buffer.push_back(bits);
  } else {
    buffer.push_back(static_cast<double>(value));
  }
}

template <class T>
T unpack_value(const double*& cursor) {
  T value;
  if constexpr (std::is_same_v<T, Vec3> || std::is_same_v<T, Mat3>) {
    std::memcpy(value.data(), cursor, doubles_of<T>() * sizeof(double));
  } else if constexpr (std::is_same_v<T, ParticleId>) {
    std::memcpy(&value, cursor, sizeof(value));
  } else {
    value = static_cast<T>(*cursor);
  }
  cursor += doubles_of<T>();
  return value;
}
}  // namespace

void ParticleSet::add(ParticleId pid, const Vec3& x, const Vec3& v, double m, double v0,
                      int material) {
  id.push_back(pid);
  position.push_back(x);
  velocity.push_back(v);
  affine_velocity.push_back(Mat3::Zero());
  deformation_gradient.push_back(Mat3::Identity());
  left_cauchy_green_ob.push_back(Mat3::Identity());
  elastic_deformation_gradient.push_back(Mat3::Identity());
  plastic_deformation_gradient.push_back(Mat3::Identity());
  yield_function.push_back(0.0);
  equivalent_plastic_strain.push_back(0.0);
  mass.push_back(m);
  volume0.push_back(v0);
  material_id.push_back(material);
}

void ParticleSet::resize(std::size_t n) {
  for_each_field([n](const char*, auto& field) { field.resize(n); });
}

void ParticleSet::permute(const std::vector<std::size_t>& order) {
  for_each_field([&order](const char*, auto& field) {
    std::remove_reference_t<decltype(field)> permuted(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) permuted[k] = field[order[k]];
    field.swap(permuted);
  });
}

std::size_t packed_doubles_per_particle() {
  std::size_t n = 0;
  ParticleSet probe;
  probe.for_each_field([&n](const char*, auto& field) {
    n += doubles_of<typename std::remove_reference_t<decltype(field)>::value_type>();
  });
  return n;
}

void pack_particle(const ParticleSet& particles, std::size_t p, std::vector<double>& buffer) {
  particles.for_each_field([&](const char*, const auto& field) { pack_value(field[p], buffer); });
}

void unpack_particles(const std::vector<double>& buffer, ParticleSet& particles) {
  const std::size_t stride = packed_doubles_per_particle();
  const double* cursor = buffer.data();
  const double* end = buffer.data() + buffer.size();
  while (cursor + stride <= end) {
    particles.for_each_field([&](const char*, auto& field) {
      using T = typename std::remove_reference_t<decltype(field)>::value_type;
      field.push_back(unpack_value<T>(cursor));
    });
  }
}

}  // namespace viscompm::particles
