// Scenes built in code for the tests (the same structs read_scene fills).
#pragma once

#include <filesystem>
#include <sstream>
#include <string>

#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/materials/oldroyd_b.hpp"
#include "viscompm/materials/registry.hpp"
#include "viscompm/parallel/communicator.hpp"
#include "viscompm/scene/scene.hpp"

namespace viscompm::testkit {

inline scene::SceneConfig base_scene(const Vec3& upper, double dx) {
  scene::SceneConfig s;
  s.file = "test";
  s.name = "test";
  s.grid.lower_corner = Vec3::Zero();
  s.grid.upper_corner = upper;
  s.grid.cell_size = dx;
  s.grid.walls = boundary::ContactType::separating;
  s.simulation.gravity = Vec3::Zero();
  s.simulation.cfl = 10.0;
  s.newton.tolerance = 1e-9;
  s.newton.max_iterations = 30;
  return s;
}

inline scene::MaterialSettings oldroyd_b_material(const std::string& name, double density, double mu, double lambda,
                                                  double viscosity, const std::string& convention, double wi) {
  scene::MaterialSettings m;
  m.name = name;
  m.model = "oldroyd_b";
  // Every declared parameter: the defaults (the strain update), then these.
  for (const auto& spec : materials::find_model("oldroyd_b")->parameters) m.values.set(spec.name, spec.default_value);
  m.values.set("Density", density);
  m.values.set("Shear modulus", mu);
  m.values.set("Lame lambda", lambda);
  m.values.set("Newtonian viscosity", viscosity);
  m.values.set("Viscosity convention", convention);
  m.values.set("Weissenberg number", wi);
  return m;
}

inline scene::BodySettings box_body(const std::string& material, const Vec3& lo, const Vec3& hi, const Vec3& v) {
  scene::BodySettings b;
  b.name = "body";
  b.shape = scene::ShapeKind::box;
  b.lower_corner = lo;
  b.upper_corner = hi;
  b.material = material;
  b.velocity = v;
  return b;
}

inline scene::ColliderSettings box_collider(const std::string& name, boundary::ContactType contact, const Vec3& lo,
                                            const Vec3& hi, const Vec3& v = Vec3::Zero()) {
  scene::ColliderSettings c;
  c.name = name;
  c.shape = scene::ShapeKind::box;
  c.contact = contact;
  c.lower_corner = lo;
  c.upper_corner = hi;
  c.velocity = v;
  return c;
}

/// Belos CG with Ifpack2 Jacobi at a given relative tolerance.
inline linalg::SolverConfiguration jacobi_cg(double tolerance) {
  std::ostringstream tol;
  tol << tolerance;
  return linalg::SolverConfiguration::from_xml(
      "<ParameterList name=\"test\">"
      "<Parameter name=\"Preconditioner\" type=\"string\" value=\"Ifpack2\"/>"
      "<Parameter name=\"Ifpack2 type\" type=\"string\" value=\"RELAXATION\"/>"
      "<ParameterList name=\"Krylov parameters\">"
      "<Parameter name=\"Convergence Tolerance\" type=\"double\" value=\"" + tol.str() + "\"/>"
      "<Parameter name=\"Maximum Iterations\" type=\"int\" value=\"10000\"/></ParameterList>"
      "<ParameterList name=\"Preconditioner parameters\">"
      "<Parameter name=\"relaxation: type\" type=\"string\" value=\"Jacobi\"/></ParameterList>"
      "</ParameterList>",
      "test solver");
}

// A small sponge with grips, a bullet and gravity: shared nodes, constraints, several materials.
inline scene::SceneConfig sponge_scene() {
  auto scene = base_scene(Vec3(1.0, 1.0, 0.6), 0.05);
  scene.simulation.gravity = Vec3(0.0, -9.81, 0.0);
  scene.simulation.max_time_step = 4e-3;
  scene.newton.tolerance = 1e-10;
  scene.materials.push_back(oldroyd_b_material("sponge", 1.0, 360.0, 1400.0, 1e-3, "paper", 50.0));
  scene.materials.push_back(oldroyd_b_material("goo", 1.0, 20.0, 100.0, 0.5, "physical", 0.1));
  scene.bodies.push_back(box_body("sponge", Vec3(0.35, 0.2, 0.2), Vec3(0.65, 0.8, 0.4), Vec3(0.3, 0, 0)));
  auto goo = box_body("goo", Vec3(0.7, 0.3, 0.2), Vec3(0.85, 0.5, 0.4), Vec3(-0.5, 0.2, 0));
  goo.angular_velocity = Vec3(0, 0, 3);
  scene.bodies.push_back(goo);
  scene.colliders.push_back(box_collider("bottom", boundary::ContactType::sticky, Vec3(0.3, 0.1, 0.15), Vec3(0.7, 0.25, 0.45)));
  scene::ColliderSettings bullet;
  bullet.name = "bullet";
  bullet.shape = scene::ShapeKind::sphere;
  bullet.center = Vec3(0.25, 0.55, 0.3);
  bullet.radius = 0.08;
  bullet.contact = boundary::ContactType::slip;
  bullet.velocity = Vec3(3, 0, 0);
  scene.colliders.push_back(bullet);
  return scene;
}

/// A material of any registered model: its declared defaults, overridden by `values`.
inline scene::MaterialSettings model_material(const std::string& name, const std::string& model,
                                              const std::vector<std::pair<std::string, ParameterValue>>& values) {
  scene::MaterialSettings m;
  m.name = name;
  m.model = model;
  for (const auto& spec : materials::find_model(model)->parameters) m.values.set(spec.name, spec.default_value);
  for (const auto& [parameter, value] : values) m.values.set(parameter, value);
  return m;
}

// Every model in one scene (the pie of Figure 5.8 has a stiff crust and a soft cream): blocks of
// each thrown at a sticky table and at each other, with gravity, so that all of them deform,
// flow plastically and migrate between ranks.
inline scene::SceneConfig mixed_models_scene() {
  auto scene = base_scene(Vec3(1.2, 0.8, 0.5), 0.05);
  scene.simulation.gravity = Vec3(0.0, -9.81, 0.0);
  scene.simulation.max_time_step = 4e-3;
  scene.newton.tolerance = 1e-10;
  const std::pair<std::string, ParameterValue> rho{"Density", 1.0}, mu{"Shear modulus", 200.0},
      lambda{"Lame lambda", 800.0};
  scene.materials.push_back(model_material("crust", "neo_hookean", {rho, {"Shear modulus", 2000.0}, {"Lame lambda", 8000.0}}));
  scene.materials.push_back(model_material("cream", "oldroyd_b", {rho, {"Shear modulus", 5.0}, {"Lame lambda", 50.0},
                                                                  {"Weissenberg number", 0.05}, {"Strain update", std::string("spd")},
                                                                  {"Newtonian viscosity", 0.01}}));
  scene.materials.push_back(model_material("goo", "oldroyd_b", {rho, mu, lambda, {"Weissenberg number", 0.1},
                                                                {"Strain update", std::string("f_e")}}));
  scene.materials.push_back(model_material("foam", "herschel_bulkley", {rho, mu, lambda, {"Yield stress", 0.02},
                                                                        {"Plastic viscosity", 0.05}, {"Flow index", 0.6}}));
  scene.materials.push_back(model_material("paste", "bingham", {rho, mu, lambda, {"Yield stress", 0.02},
                                                                {"Plastic viscosity", 0.05}}));
  scene.materials.push_back(model_material("snow", "svd_plasticity", {rho, mu, lambda, {"Critical compression", 0.01},
                                                                      {"Critical stretch", 0.005}, {"Hardening coefficient", 10.0}}));
  scene.materials.push_back(model_material("metal", "von_mises", {rho, mu, lambda, {"Yield stress", 2.0},
                                                                  {"Hardening modulus", 50.0}}));
  const double y0 = 0.25, size = 0.15;
  const char* names[] = {"crust", "goo", "foam", "paste", "snow", "metal"};
  for (int k = 0; k < 6; ++k) {
    const Vec3 lo(0.12 + 0.16 * k, y0, 0.15);
    auto body = box_body(names[k], lo, lo + Vec3(0.14, size, size), Vec3(k % 2 ? -1.5 : 1.5, -2.0, 0.0));
    body.name = names[k];
    scene.bodies.push_back(body);
  }
  // The cream sits on the crust.
  auto cream = box_body("cream", Vec3(0.12, y0 + size, 0.15), Vec3(0.26, y0 + size + 0.1, 0.3), Vec3(1.5, -2.0, 0.0));
  cream.name = "cream";
  scene.bodies.push_back(cream);
  scene.colliders.push_back(box_collider("table", boundary::ContactType::sticky, Vec3(0.0, 0.0, 0.0), Vec3(1.2, 0.2, 0.5)));
  return scene;
}

// A fresh, empty directory viscompm_NAME_npN under the system's temporary directory (collective).
inline std::string work_directory(const parallel::Communicator& comm, const std::string& name) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("viscompm_" + name + "_np" + std::to_string(comm.size()))).string();
  if (comm.is_root()) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  comm.barrier();
  return dir;
}

}  // namespace viscompm::testkit
