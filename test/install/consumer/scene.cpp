// Uses the installed library: reads the installed default scene (Trilinos parameter lists) and
// checks what it holds.
#include <cstdio>

#include "viscompm/scene/scene.hpp"

int main() {
  const viscompm::scene::SceneConfig scene = viscompm::scene::read_scene(SCENE);
  std::printf("%s: %zu materials, %zu bodies, %zu colliders, cell size %g\n", scene.name.c_str(),
              scene.materials.size(), scene.bodies.size(), scene.colliders.size(), scene.grid.cell_size);
  return scene.name == "shooting_sponge" && !scene.bodies.empty() && scene.grid.cell_size > 0.0 ? 0 : 1;
}
