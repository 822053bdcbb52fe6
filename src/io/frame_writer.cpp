#include "viscompm/io/frame_writer.hpp"

#include <cstdio>
#include <functional>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <type_traits>

#include "viscompm/core/error.hpp"
#include "viscompm/io/particle_file.hpp"

namespace viscompm::io {

std::string frame_file_name(int frame) {
  std::ostringstream name;
  name << "frame_" << std::setw(5) << std::setfill('0') << frame << ".h5";
  return name.str();
}

FrameInfo write_frame(const std::string& directory, FrameInfo info, const particles::ParticleSet& particles,
                      const materials::MaterialList& materials, const parallel::Communicator& comm,
                      const FrameExtras& extras, const WritePieces& pieces) {
  FileAttributes attributes;
  attributes.reals["time"] = info.time;
  attributes.integers["step"] = info.step;
  attributes.integers["frame"] = info.frame;
  // Every stored per-particle quantity, and b^E of (5.5) from each particle's material.
  const std::vector<DerivedTensor> derived = {{"left_cauchy_green_elastic", [&](std::size_t p) {
                                                 return materials[particles.material_id[p]]->left_cauchy_green_elastic(particles, p);
                                               }}};
  std::vector<Table> tables;
  if (!extras.collider_triangles.empty()) {
    tables.push_back({"colliders/vertices", 3, extras.collider_vertices, {}});
    tables.push_back({"colliders/triangles", 3, {}, extras.collider_triangles});
    tables.push_back({"colliders/collider_id", 1, {}, extras.collider_id});
    info.collider_vertices = static_cast<std::int64_t>(extras.collider_vertices.size() / 3);
    info.collider_triangles = static_cast<std::int64_t>(extras.collider_triangles.size() / 3);
    attributes.integers["collider_vertex_count"] = info.collider_vertices;
    attributes.integers["collider_triangle_count"] = info.collider_triangles;
  }
  attributes.reals["emitted_mass"] = extras.emitted_mass;
  info.particle_count = write_particle_file((std::filesystem::path(directory) / frame_file_name(info.frame)).string(),
                                            attributes, particles, derived, material_names(materials), comm, tables, pieces);
  return info;
}

std::string material_names(const materials::MaterialList& materials) {
  std::string names;
  for (std::size_t k = 0; k < materials.size(); ++k) names += (k ? "," : "") + materials[k]->name();
  return names;
}

void write_xdmf(const std::string& directory, const std::vector<FrameInfo>& frames) {
  const std::filesystem::path path = std::filesystem::path(directory) / "particles.xdmf";
  const std::string temporary = path.string() + ".tmp";
  {
    std::ofstream out(temporary);
    out << "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"2.0\">\n <Domain>\n"
        << "  <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (const auto& f : frames) {
      const std::string file = frame_file_name(f.frame);
      const auto n = f.particle_count;
      auto item = [&](const std::string& dataset, const std::string& dims, const char* number, int precision) {
        std::ostringstream s;
        s << "<DataItem Dimensions=\"" << dims << "\" NumberType=\"" << number << "\" Precision=\"" << precision
          << "\" Format=\"HDF\">" << file << ":/particles/" << dataset << "</DataItem>";
        return s.str();
      };
      const std::string n1 = std::to_string(n), n3 = n1 + " 3", n33 = n1 + " 3 3";
      out << "   <Grid Name=\"frame_" << f.frame << "\" GridType=\"Uniform\">\n"
          << "    <Time Value=\"" << std::setprecision(17) << f.time << "\"/>\n"
          << "    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n << "\" NodesPerElement=\"1\"/>\n"
          << "    <Geometry GeometryType=\"XYZ\">" << item("position", n3, "Float", 8) << "</Geometry>\n";
      auto attribute = [&](const std::string& name, const char* type, const std::string& dataset, const std::string& dims,
                           const char* number, int precision) {
        out << "    <Attribute Name=\"" << name << "\" AttributeType=\"" << type << "\" Center=\"Node\">"
            << item(dataset, dims, number, precision) << "</Attribute>\n";
      };
      // One attribute per stored field (position is the geometry), and b^E.
      particles::ParticleSet().for_each_field([&](const char* name, const auto& field) {
        using T = typename std::decay_t<decltype(field)>::value_type;
        if (std::string(name) == "position") return;
        if constexpr (std::is_same_v<T, Vec3>) attribute(name, "Vector", name, n3, "Float", 8);
        else if constexpr (std::is_same_v<T, Mat3>) attribute(name, "Tensor", name, n33, "Float", 8);
        else if constexpr (std::is_same_v<T, ParticleId>) attribute(name, "Scalar", name, n1, "Int", 8);
        else if constexpr (std::is_same_v<T, int>) attribute(name, "Scalar", name, n1, "Int", 4);
        else attribute(name, "Scalar", name, n1, "Float", 8);
      });
      attribute("left_cauchy_green_elastic", "Tensor", "left_cauchy_green_elastic", n33, "Float", 8);
      out << "   </Grid>\n";
    }
    out << "  </Grid>\n";
    // The colliders' surfaces, frame by frame (a second collection: ParaView shows both).
    bool any_colliders = false;
    for (const auto& f : frames) any_colliders |= f.collider_triangles > 0;
    if (any_colliders) {
      out << "  <Grid Name=\"colliders\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
      for (const auto& f : frames) {
        if (f.collider_triangles == 0) continue;
        const std::string file = frame_file_name(f.frame);
        const std::string nv = std::to_string(f.collider_vertices), nt = std::to_string(f.collider_triangles);
        out << "   <Grid Name=\"colliders_" << f.frame << "\" GridType=\"Uniform\">\n"
            << "    <Time Value=\"" << std::setprecision(17) << f.time << "\"/>\n"
            << "    <Topology TopologyType=\"Triangle\" NumberOfElements=\"" << nt << "\">"
            << "<DataItem Dimensions=\"" << nt << " 3\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">" << file
            << ":/colliders/triangles</DataItem></Topology>\n"
            << "    <Geometry GeometryType=\"XYZ\"><DataItem Dimensions=\"" << nv
            << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << file
            << ":/colliders/vertices</DataItem></Geometry>\n"
            << "    <Attribute Name=\"collider_id\" AttributeType=\"Scalar\" Center=\"Cell\"><DataItem Dimensions=\"" << nt
            << "\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">" << file
            << ":/colliders/collider_id</DataItem></Attribute>\n"
            << "   </Grid>\n";
      }
      out << "  </Grid>\n";
    }
    out << " </Domain>\n</Xdmf>\n";
    out.close();
    std::error_code error;
    if (!out) {
      std::filesystem::remove(temporary, error);
      throw SimulationError("cannot write " + temporary + ": " + write_failure_reason(temporary));
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) throw SimulationError("cannot write " + path.string() + ": " + write_failure_reason(path.string()));
}

}  // namespace viscompm::io
