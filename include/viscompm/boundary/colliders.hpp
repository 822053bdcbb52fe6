// Grid-based collisions (§3.4 "perform grid-based collisions", Stomakhin et al. 2013): static or
// kinematic solids and the walls of the domain constrain the velocities of the grid nodes they
// cover. A constraint at node i is a projection P_i onto the free directions and a prescribed
// velocity u_i for the rest: v_i = P_i v_i + (I − P_i) u_i. Sticky: P = 0; slip: the normal
// component is prescribed; separating: slip only while the node moves into the solid. Dirichlet
// grips (the sponge scenes) are sticky colliders.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "viscompm/core/shape.hpp"
#include "viscompm/grid/grid_layout.hpp"
#include "viscompm/particles/particle_set.hpp"

namespace viscompm::boundary {

enum class ContactType { sticky, slip, separating };
ContactType contact_type_from_name(const std::string& name);

struct Collider {
  std::string name;
  Shape shape;                     ///< at time `start_time`
  ContactType type = ContactType::sticky;
  Vec3 velocity = Vec3::Zero();    ///< kinematic: translates with this velocity
  double start_time = 0.0;         ///< moves during [start_time, stop_time], rests otherwise
  double stop_time = std::numeric_limits<double>::infinity();

  /// Velocity of the solid at time t (zero outside its moving interval).
  Vec3 velocity_at(double t) const;
  /// The shape at time t.
  Shape shape_at(double t) const;
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
  Boundary(std::vector<Collider> colliders, DomainWalls walls)
      : colliders_(std::move(colliders)), walls_(walls) {}

  /// Constraints at time t for the nodes of `layout`; `v_trial` (the unconstrained predicted
  /// velocity) decides which separating contacts are active.
  NodeConstraints constrain(const grid::GridLayout& layout, double t, const NodeVectorField& v_trial) const;

  /// Keeps particles where their stencils stay inside the grid; returns how many were moved.
  std::size_t clamp_particles(const grid::GridGeometry& geometry, std::vector<Vec3>& positions) const;
  /// Removes the particles whose stencils would leave the grid; returns how many.
  std::size_t delete_outside_particles(const grid::GridGeometry& geometry, particles::ParticleSet& particles) const;

  const std::vector<Collider>& colliders() const { return colliders_; }
  const DomainWalls& walls() const { return walls_; }

 private:
  std::vector<Collider> colliders_;
  DomainWalls walls_;
};

}  // namespace viscompm::boundary
