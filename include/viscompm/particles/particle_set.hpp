// Particle storage, one array per quantity (structure of arrays). Every per-particle array is
// listed once in for_each_field, which reordering, migration, checkpointing and output share.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "viscompm/core/types.hpp"

namespace viscompm::particles {

struct ParticleSet {
  std::vector<ParticleId> id;                 ///< stable global id
  std::vector<Vec3> position;                 ///< x_p
  std::vector<Vec3> velocity;                 ///< v_p
  std::vector<Mat3> affine_velocity;          ///< C_p = B_p D_p^{-1} of APIC (zero for PIC/FLIP)
  std::vector<Mat3> deformation_gradient;     ///< F_p
  std::vector<Mat3> left_cauchy_green_ob;     ///< b_OB^E of §5.4.4 (the stored S of Appendix A); b_HB of
                                              ///< §4.6.2 for the Herschel–Bulkley-like models
  std::vector<Mat3> elastic_deformation_gradient;  ///< F_E of §4.1 (svd_plasticity, von_mises); the f_e of
                                                   ///< §4.7 for oldroyd_b with the f_e update
  std::vector<Mat3> plastic_deformation_gradient;  ///< F_P of §4.1, F = F_E F_P (svd_plasticity, von_mises)
  std::vector<double> yield_function;         ///< the model's yield function at its last strain update:
                                              ///< > 0 when that step flowed plastically (doc/materials.md)
  std::vector<double> equivalent_plastic_strain;  ///< accumulated plastic strain (von_mises: ε of §4.2.6)
  std::vector<double> mass;                   ///< m_p
  std::vector<double> volume0;                ///< V_p^0
  std::vector<int> material_id;               ///< index into the scene's material list

  std::size_t size() const { return id.size(); }
  bool empty() const { return id.empty(); }

  /// Calls f(name, vector&) for every per-particle array. The name is the HDF5 dataset name.
  template <class F>
  void for_each_field(F&& f) { visit_fields(*this, f); }
  template <class F>
  void for_each_field(F&& f) const { visit_fields(*this, f); }

  /// Appends one particle with identity strains, no plastic history and zero affine velocity.
  void add(ParticleId pid, const Vec3& x, const Vec3& v, double m, double v0, int material);
  void resize(std::size_t n);
  /// Keeps particle order[k] at position k (order may be a subset: the rest is dropped).
  void permute(const std::vector<std::size_t>& order);

 private:
  template <class Self, class F>
  static void visit_fields(Self& self, F& f) {
    f("id", self.id);
    f("position", self.position);
    f("velocity", self.velocity);
    f("affine_velocity", self.affine_velocity);
    f("deformation_gradient", self.deformation_gradient);
    f("left_cauchy_green_ob", self.left_cauchy_green_ob);
    f("elastic_deformation_gradient", self.elastic_deformation_gradient);
    f("plastic_deformation_gradient", self.plastic_deformation_gradient);
    f("yield_function", self.yield_function);
    f("equivalent_plastic_strain", self.equivalent_plastic_strain);
    f("mass", self.mass);
    f("volume0", self.volume0);
    f("material_id", self.material_id);
  }
};

/// Number of doubles one particle occupies in a packed buffer (migration, checkpoints).
std::size_t packed_doubles_per_particle();
/// Appends particle p to `buffer`.
void pack_particle(const ParticleSet& particles, std::size_t p, std::vector<double>& buffer);
/// Appends the particles stored in `buffer` (a sequence of packed particles).
void unpack_particles(const std::vector<double>& buffer, ParticleSet& particles);

}  // namespace viscompm::particles
