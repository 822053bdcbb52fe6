#include "viscompm/simulation/scene_objects.hpp"

#include "viscompm/core/error.hpp"
#include "viscompm/particles/sampling.hpp"

namespace viscompm::simulation {

std::vector<boundary::Collider> make_colliders(const scene::SceneConfig& scene) {
  std::vector<boundary::Collider> colliders;
  for (const auto& c : scene.colliders) colliders.push_back(scene::collider_of(c));
  return colliders;
}

std::vector<particles::Emitter> make_emitters(const scene::SceneConfig& scene, const grid::GridGeometry& grid,
                                              const materials::MaterialList& materials) {
  // Ids after every body's lattice; layer k of all emitters takes one block of `stride` ids.
  ParticleId base = 0;
  for (const auto& body : scene.bodies) {
    particles::BodySampling sampling;
    sampling.shape = scene::shape_of(body);
    sampling.particles_per_cell = body.particles_per_cell;
    base += particles::lattice_size(sampling, grid);
  }
  std::vector<particles::EmitterSpec> specs;
  ParticleId stride = 0;
  std::vector<ParticleId> offsets;
  for (const auto& e : scene.emitters) {
    particles::EmitterSpec spec;
    spec.name = e.name;
    spec.nozzle = scene::shape_of(e);
    spec.velocity = e.velocity;
    spec.mass_rate = e.mass_rate;
    spec.start_time = e.start_time;
    spec.stop_time = e.stop_time;
    spec.particles_per_cell = e.particles_per_cell;
    spec.material_id = e.material_id;
    spec.density = materials[spec.material_id]->density();
    const std::size_t sites = particles::nozzle_sites(spec.nozzle, spec.velocity, grid.dx / e.particles_per_cell).size();
    if (sites == 0) throw parameter_error(scene.file, "Emitters/" + e.name + "/Shape", "the nozzle holds no particle site");
    offsets.push_back(stride);
    stride += static_cast<ParticleId>(sites);
    specs.push_back(spec);
  }
  std::vector<particles::Emitter> emitters;
  for (std::size_t k = 0; k < specs.size(); ++k) emitters.emplace_back(specs[k], grid, base, stride, offsets[k]);
  return emitters;
}

std::vector<boundary::Inflow> make_inflows(const scene::SceneConfig& scene) {
  std::vector<boundary::Inflow> inflows;
  for (const auto& e : scene.emitters) inflows.push_back({scene::shape_of(e), e.velocity, e.start_time, e.stop_time});
  return inflows;
}

std::vector<particles::MaterialRegion> make_regions(const scene::SceneConfig& scene, int body,
                                                    const materials::MaterialList& materials) {
  std::vector<particles::MaterialRegion> regions;
  for (const auto& r : scene.regions) {
    if (r.body_id != body) continue;
    particles::MaterialRegion region;
    region.shape = scene::shape_of(r);
    region.material_id = r.material_id;
    region.density = materials[region.material_id]->density();
    regions.push_back(region);
  }
  return regions;
}

}  // namespace viscompm::simulation
