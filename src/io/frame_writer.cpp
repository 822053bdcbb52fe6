#include "viscompm/io/frame_writer.hpp"

#include <hdf5.h>

#include <cstdio>
#include <functional>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <type_traits>

#include "viscompm/core/error.hpp"

namespace viscompm::io {

namespace {
void check(herr_t status, const char* what) {
  if (status < 0) throw SimulationError(std::string("HDF5 error: ") + what);
}

// A particle dataset of shape n_total × extra dims, each rank writing its rows at `offset`.
template <class T>
void write_rows(hid_t group, const char* name, hid_t type, const std::vector<T>& data, std::vector<hsize_t> row_shape,
                hsize_t n_local, hsize_t offset, hsize_t n_total) {
  std::vector<hsize_t> dims = {n_total}, start = {offset}, count = {n_local};
  for (hsize_t d : row_shape) {
    dims.push_back(d);
    start.push_back(0);
    count.push_back(d);
  }
  const int rank = static_cast<int>(dims.size());
  const hid_t file_space = H5Screate_simple(rank, dims.data(), nullptr);
  const hid_t dataset = H5Dcreate2(group, name, type, file_space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const hid_t memory_space = H5Screate_simple(rank, count.data(), nullptr);
  if (n_local > 0) {
    check(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr), "select");
  } else {
    H5Sselect_none(file_space);
    H5Sselect_none(memory_space);
  }
  const hid_t transfer = H5Pcreate(H5P_DATASET_XFER);
  H5Pset_dxpl_mpio(transfer, H5FD_MPIO_COLLECTIVE);
  check(H5Dwrite(dataset, type, memory_space, file_space, transfer, data.data()), name);
  H5Pclose(transfer);
  H5Sclose(memory_space);
  H5Dclose(dataset);
  H5Sclose(file_space);
}

template <class T>
void write_attribute(hid_t object, const char* name, hid_t type, T value) {
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attribute = H5Acreate2(object, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  check(H5Awrite(attribute, type, &value), name);
  H5Aclose(attribute);
  H5Sclose(space);
}

// Row-major n×3×3 copy: entry [p][i][j] = M_p(i, j).
std::vector<double> tensors(std::size_t n, const std::function<Mat3(std::size_t)>& tensor) {
  std::vector<double> out(9 * n);
  for (std::size_t p = 0; p < n; ++p) {
    const Mat3 m = tensor(p);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) out[9 * p + 3 * i + j] = m(i, j);
  }
  return out;
}

std::vector<double> vectors(const std::vector<Vec3>& v) {
  std::vector<double> out(3 * v.size());
  for (std::size_t p = 0; p < v.size(); ++p)
    for (int d = 0; d < 3; ++d) out[3 * p + d] = v[p][d];
  return out;
}
}  // namespace

std::string frame_file_name(int frame) {
  std::ostringstream name;
  name << "frame_" << std::setw(5) << std::setfill('0') << frame << ".h5";
  return name.str();
}

FrameInfo write_frame(const std::string& directory, FrameInfo info, const particles::ParticleSet& particles,
                      const materials::MaterialList& materials, const parallel::Communicator& comm) {
  const std::filesystem::path final_path = std::filesystem::path(directory) / frame_file_name(info.frame);
  const std::string temporary = final_path.string() + ".tmp";
  const auto n_local = static_cast<long long>(particles.size());
  long long offset = 0, n_total = 0;
  MPI_Exscan(&n_local, &offset, 1, MPI_LONG_LONG, MPI_SUM, comm.comm());
  if (comm.rank() == 0) offset = 0;
  MPI_Allreduce(&n_local, &n_total, 1, MPI_LONG_LONG, MPI_SUM, comm.comm());
  info.particle_count = n_total;

  const hid_t access = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_fapl_mpio(access, comm.comm(), MPI_INFO_NULL);
  const hid_t file = H5Fcreate(temporary.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access);
  H5Pclose(access);
  if (file < 0) throw SimulationError("cannot create " + temporary);
  write_attribute(file, "time", H5T_NATIVE_DOUBLE, info.time);
  write_attribute(file, "step", H5T_NATIVE_INT64, static_cast<std::int64_t>(info.step));
  write_attribute(file, "frame", H5T_NATIVE_INT64, static_cast<std::int64_t>(info.frame));
  const hid_t group = H5Gcreate2(file, "particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);

  const std::size_t n = particles.size();
  const auto rows = static_cast<hsize_t>(n_local), start = static_cast<hsize_t>(offset),
             total = static_cast<hsize_t>(n_total);
  // Every stored per-particle quantity, then b^E of (5.5) computed by each particle's material.
  particles.for_each_field([&](const char* name, const auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    if constexpr (std::is_same_v<T, Vec3>) {
      write_rows(group, name, H5T_NATIVE_DOUBLE, vectors(field), {3}, rows, start, total);
    } else if constexpr (std::is_same_v<T, Mat3>) {
      write_rows(group, name, H5T_NATIVE_DOUBLE, tensors(n, [&](std::size_t p) { return field[p]; }), {3, 3}, rows,
                 start, total);
    } else if constexpr (std::is_same_v<T, ParticleId>) {
      write_rows(group, name, H5T_NATIVE_INT64, field, {}, rows, start, total);
    } else if constexpr (std::is_same_v<T, int>) {
      write_rows(group, name, H5T_NATIVE_INT, field, {}, rows, start, total);
    } else {
      write_rows(group, name, H5T_NATIVE_DOUBLE, field, {}, rows, start, total);
    }
  });
  write_rows(group, "left_cauchy_green_elastic", H5T_NATIVE_DOUBLE, tensors(n, [&](std::size_t p) {
               return materials[particles.material_id[p]]->left_cauchy_green_elastic(particles, p);
             }), {3, 3}, rows, start, total);
  // Material names, indexed by material_id, as an attribute of the group.
  std::string names;
  for (std::size_t k = 0; k < materials.size(); ++k) names += (k ? "," : "") + materials[k]->name();
  const hid_t string_type = H5Tcopy(H5T_C_S1);
  H5Tset_size(string_type, names.size() + 1);
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attribute = H5Acreate2(group, "material_names", string_type, space, H5P_DEFAULT, H5P_DEFAULT);
  check(H5Awrite(attribute, string_type, names.c_str()), "material_names");
  H5Aclose(attribute);
  H5Sclose(space);
  H5Tclose(string_type);

  H5Gclose(group);
  check(H5Fclose(file), "close");
  comm.barrier();
  if (comm.is_root()) std::filesystem::rename(temporary, final_path);
  comm.barrier();
  return info;
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
    out << "  </Grid>\n </Domain>\n</Xdmf>\n";
  }
  std::filesystem::rename(temporary, path);
}

}  // namespace viscompm::io
