// Grid-based collisions (§3.4 "perform grid-based collisions", Stomakhin et al. 2013): static or
// kinematic solids and the walls of the domain constrain the velocities of the grid nodes they
// cover. A constraint at node i is a projection P_i onto the free directions and a prescribed
// velocity u_i for the rest: v_i = P_i v_i + (I − P_i) u_i. Sticky: P = 0; slip: the normal
// component is prescribed; separating: slip only while the node moves into the solid. Dirichlet
// grips (the sponge scenes) are sticky colliders. A collider moves rigidly (RigidMotion), so u_i
// is the rigid velocity v0 + ω × (x_i − c) plus, for a belt, the velocity of its surface.
// Emitter nozzles impose their inflow velocity on the nodes they cover (Inflow). After g2p,
// particle-based collisions (§5.5.1, last step) project the velocity of every particle that would
// enter a collider during the step, so that thin or fast solids are not crossed between nodes.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "viscompm/boundary/rigid_motion.hpp"
#include "viscompm/core/shape.hpp"
#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::boundary {

enum class ContactType { sticky, slip, separating };

struct Collider {
  std::string name;
  Shape shape;                     ///< at the start time (rest position)
  ContactType type = ContactType::sticky;
  RigidMotion motion;              ///< static by default
  Vec3 surface_velocity = Vec3::Zero();  ///< tangential velocity of the surface of a solid at rest (a belt)

  /// The solid's transform at time t (rest frame → world).
  RigidTransform transform_at(double t) const { return motion.transform_at(t); }
  /// Signed distance of x (world) to the solid at time t (negative inside).
  double signed_distance(const Vec3& x, double t) const;
  /// Outward unit normal at x (world) at time t.
  Vec3 normal(const Vec3& x, double t) const;
  /// Velocity of the solid at x (world) at time t: rigid velocity plus the tangential part of
  /// the surface velocity (turned with the solid).
  Vec3 velocity_at(const Vec3& x, double t) const;
  /// An upper bound of the speed of any point of the solid (for the CFL condition).
  double max_speed() const;
};

/// An emitter's nozzle: nodes inside it move with the inflow velocity while it emits.
struct Inflow {
  Shape nozzle;
  Vec3 velocity = Vec3::Zero();
  double start_time = 0.0;
  double stop_time = std::numeric_limits<double>::infinity();
  bool active(double t) const { return t >= start_time && t < stop_time; }
};

struct DomainWalls {
  ContactType type = ContactType::separating;
  int thickness = 2;  ///< nodes closer than this many cells to a face of the grid are walls
};

/// Per-node constraints of one step, on the layout's local nodes.
struct NodeConstraints {
  std::vector<Mat3> projection;     ///< P_i (identity: free node)
  NodeVectorField prescribed;       ///< (I − P_i) u_i
  std::size_t constrained_count = 0;

  /// v ← P v + (I − P) u.
  void apply(NodeVectorField& v) const;
  /// dv ← P dv (a Newton direction keeps prescribed components).
  void project(NodeVectorField& dv) const;
};

class Boundary {
 public:
  Boundary() = default;
  Boundary(std::vector<Collider> colliders, DomainWalls walls, std::vector<Inflow> inflows = {})
      : colliders_(std::move(colliders)), walls_(walls), inflows_(std::move(inflows)) {}

  /// Constraints at time t for the nodes of `layout`; `v_trial` (the unconstrained predicted
  /// velocity) decides which separating contacts are active.
  NodeConstraints constrain(const grid::GridLayout& layout, double t, const NodeVectorField& v_trial) const;

  /// Particle-based collisions after g2p (§5.5.1): every particle whose path x → x + Δt v during
  /// [t, t + Δt] would enter a collider gets its velocity relative to the solid projected as the
  /// collider's contact says (sticky: the solid's velocity; slip and separating: the approaching
  /// normal component removed). Returns how many particles were changed.
  std::size_t collide_particles(const std::vector<Vec3>& positions, std::vector<Vec3>& velocities, double t,
                                double dt) const;

  /// Keeps particles where their stencils stay inside the grid; returns how many were moved.
  std::size_t clamp_particles(const grid::GridGeometry& geometry, std::vector<Vec3>& positions) const;
  /// Removes the particles whose stencils would leave the grid; returns how many.
  std::size_t delete_outside_particles(const grid::GridGeometry& geometry, particles::ParticleSet& particles) const;

  const std::vector<Collider>& colliders() const { return colliders_; }
  const DomainWalls& walls() const { return walls_; }
  const std::vector<Inflow>& inflows() const { return inflows_; }

 private:
  std::vector<Collider> colliders_;
  DomainWalls walls_;
  std::vector<Inflow> inflows_;
};

}  // namespace viscompm::boundary
