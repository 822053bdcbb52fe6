#include "viscompm/io/particle_file.hpp"

#include <hdf5.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <type_traits>

#include "viscompm/core/error.hpp"

namespace viscompm::io {

namespace {
// The first failure of a collective write, if any. Writes go on after a failure so that every
// rank makes the same sequence of collective calls; the ranks agree on the outcome at the end.
struct WriteStatus {
  std::string failed;  ///< what failed first on this rank, empty if nothing
  void check(long long status, const std::string& what) {
    if (status < 0 && failed.empty()) failed = what;
  }
};

template <class T>
hid_t memory_type() {
  if constexpr (std::is_same_v<T, ParticleId>) return H5T_NATIVE_INT64;
  else if constexpr (std::is_same_v<T, int>) return H5T_NATIVE_INT;
  else return H5T_NATIVE_DOUBLE;
}

// Per-row shape and the flattening of a field's element (row-major: tensor [p][i][j] = M_p(i, j)).
template <class T>
std::vector<hsize_t> row_shape() {
  if constexpr (std::is_same_v<T, Vec3>) return {3};
  else if constexpr (std::is_same_v<T, Mat3>) return {3, 3};
  else return {};
}

template <class T>
auto flatten(const std::vector<T>& field) {
  if constexpr (std::is_same_v<T, Vec3> || std::is_same_v<T, Mat3>) {
    constexpr int n = std::is_same_v<T, Vec3> ? 3 : 9;
    std::vector<double> out(n * field.size());
    for (std::size_t p = 0; p < field.size(); ++p) {
      if constexpr (std::is_same_v<T, Vec3>) {
        for (int d = 0; d < 3; ++d) out[3 * p + d] = field[p][d];
      } else {
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) out[9 * p + 3 * i + j] = field[p](i, j);
      }
    }
    return out;
  } else {
    return field;
  }
}

template <class T>
void unflatten(const std::vector<double>& flat, std::vector<T>& field) {
  for (std::size_t p = 0; p < field.size(); ++p) {
    if constexpr (std::is_same_v<T, Vec3>) {
      for (int d = 0; d < 3; ++d) field[p][d] = flat[3 * p + d];
    } else {
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) field[p](i, j) = flat[9 * p + 3 * i + j];
    }
  }
}

// Creates dataset `name` of n_total rows and writes this rank's n_local rows at `offset` in
// `pieces` collective writes of at most `piece_rows` rows each — the same number on every rank; a
// rank whose rows are all written writes nothing in the later ones. `rows(first, count)` gives a
// pointer to rows [first, first + count) of this rank, flattened; after each piece `go_on()`
// (collective) says whether to continue.
template <class Rows, class GoOn>
void write_pieces(WriteStatus& status, hid_t group, const std::string& name, hid_t type,
                  const std::vector<hsize_t>& shape, hsize_t n_local, hsize_t offset, hsize_t n_total,
                  hsize_t piece_rows, hsize_t pieces, Rows rows, GoOn go_on) {
  std::vector<hsize_t> dims = {n_total};
  for (hsize_t d : shape) dims.push_back(d);
  const int rank = static_cast<int>(dims.size());
  const hid_t file_space = H5Screate_simple(rank, dims.data(), nullptr);
  const hid_t dataset = H5Dcreate2(group, name.c_str(), type, file_space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  status.check(dataset, "create dataset " + name);
  const hid_t transfer = H5Pcreate(H5P_DATASET_XFER);
  H5Pset_dxpl_mpio(transfer, H5FD_MPIO_COLLECTIVE);
  for (hsize_t k = 0; k < pieces; ++k) {
    const hsize_t first = std::min(n_local, k * piece_rows), count = std::min(n_local - first, piece_rows);
    std::vector<hsize_t> start = {offset + first}, counts = {count};
    for (hsize_t d : shape) {
      start.push_back(0);
      counts.push_back(d);
    }
    const hid_t memory_space = H5Screate_simple(rank, counts.data(), nullptr);
    if (count > 0) {
      status.check(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start.data(), nullptr, counts.data(), nullptr), name);
    } else {
      H5Sselect_none(file_space);
      H5Sselect_none(memory_space);
    }
    status.check(H5Dwrite(dataset, type, memory_space, file_space, transfer, rows(first, count)), "write " + name);
    H5Sclose(memory_space);
    if (!go_on()) break;
  }
  H5Pclose(transfer);
  status.check(H5Dclose(dataset), "close " + name);
  H5Sclose(file_space);
}

// A small dataset in one piece (root arrays, tables): no agreement inside it.
template <class D>
void write_rows(WriteStatus& status, hid_t group, const std::string& name, hid_t type, const std::vector<D>& data,
                const std::vector<hsize_t>& shape, hsize_t n_local, hsize_t offset, hsize_t n_total) {
  write_pieces(status, group, name, type, shape, n_local, offset, n_total, n_local, 1,
               [&](hsize_t, hsize_t) { return data.data(); }, [] { return true; });
}

// Rows [first, first + count) of a field, flattened (row-major) for Vec3 and Mat3.
template <class T>
const void* field_rows(const std::vector<T>& field, hsize_t first, hsize_t count, std::vector<double>& buffer) {
  if constexpr (std::is_same_v<T, Vec3> || std::is_same_v<T, Mat3>) {
    buffer = flatten(std::vector<T>(field.begin() + first, field.begin() + first + count));
    return buffer.data();
  } else {
    return field.data() + first;
  }
}

// Reads rows [offset, offset + n_local) of dataset `name` (collective).
template <class D>
bool read_rows(hid_t group, const std::string& name, hid_t type, std::vector<D>& data,
               const std::vector<hsize_t>& shape, hsize_t n_local, hsize_t offset) {
  if (H5Lexists(group, name.c_str(), H5P_DEFAULT) <= 0) return false;
  const hid_t dataset = H5Dopen2(group, name.c_str(), H5P_DEFAULT);
  const hid_t file_space = H5Dget_space(dataset);
  const int rank = H5Sget_simple_extent_ndims(file_space);
  if (rank != static_cast<int>(shape.size()) + 1) {
    H5Sclose(file_space);
    H5Dclose(dataset);
    return false;
  }
  std::vector<hsize_t> start = {offset}, count = {n_local};
  hsize_t per_row = 1;
  for (hsize_t d : shape) {
    start.push_back(0);
    count.push_back(d);
    per_row *= d;
  }
  data.resize(n_local * per_row);
  const hid_t memory_space = H5Screate_simple(rank, count.data(), nullptr);
  if (n_local > 0) {
    H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
  } else {
    H5Sselect_none(file_space);
    H5Sselect_none(memory_space);
  }
  const hid_t transfer = H5Pcreate(H5P_DATASET_XFER);
  H5Pset_dxpl_mpio(transfer, H5FD_MPIO_COLLECTIVE);
  const herr_t status = H5Dread(dataset, type, memory_space, file_space, transfer, data.data());
  H5Pclose(transfer);
  H5Sclose(memory_space);
  H5Sclose(file_space);
  H5Dclose(dataset);
  return status >= 0;
}

void write_string_attribute(WriteStatus& status, hid_t object, const std::string& name, const std::string& value) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, value.size() + 1);
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attribute = H5Acreate2(object, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
  status.check(attribute, "attribute " + name);
  status.check(H5Awrite(attribute, type, value.c_str()), "attribute " + name);
  H5Aclose(attribute);
  H5Sclose(space);
  H5Tclose(type);
}

template <class T>
void write_scalar_attribute(WriteStatus& status, hid_t object, const std::string& name, hid_t type, T value) {
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attribute = H5Acreate2(object, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
  status.check(attribute, "attribute " + name);
  status.check(H5Awrite(attribute, type, &value), "attribute " + name);
  H5Aclose(attribute);
  H5Sclose(space);
}

// Every root attribute, by its HDF5 class.
herr_t collect_attribute(hid_t location, const char* name, const H5A_info_t*, void* data) {
  auto& attributes = *static_cast<FileAttributes*>(data);
  const hid_t attribute = H5Aopen(location, name, H5P_DEFAULT);
  const hid_t type = H5Aget_type(attribute);
  const H5T_class_t kind = H5Tget_class(type);
  if (kind == H5T_FLOAT) {
    double value = 0.0;
    H5Aread(attribute, H5T_NATIVE_DOUBLE, &value);
    attributes.reals[name] = value;
  } else if (kind == H5T_INTEGER) {
    std::int64_t value = 0;
    H5Aread(attribute, H5T_NATIVE_INT64, &value);
    attributes.integers[name] = value;
  } else if (kind == H5T_STRING) {
    std::string value(H5Tget_size(type), '\0');
    H5Aread(attribute, type, value.data());
    attributes.strings[name] = value.c_str();
  }
  H5Tclose(type);
  H5Aclose(attribute);
  return 0;
}
}  // namespace

namespace {
// Where a collective write stands: the ranks agree after every piece whether a write failed on
// any of them or any asks to stop (WritePieces::stop), in one collective.
struct Progress {
  const parallel::Communicator& comm;
  const WritePieces& pieces;
  const WriteStatus& status;
  int stop_signal = 0;     ///< agreed: the largest signal asked for, 0 if none
  bool abandoned = false;  ///< agreed: a write failed or a stop was asked for
  bool go_on() {
    const std::vector<std::int64_t> all =
        comm.max(std::vector<std::int64_t>{status.failed.empty() ? 0 : 1, pieces.stop ? pieces.stop() : 0});
    stop_signal = static_cast<int>(all[1]);
    abandoned = all[0] != 0 || all[1] != 0;
    return !abandoned;
  }
};

// Every stored field and the derived tensors under /particles, this rank's rows at `start`
// (collective), in pieces of at most WritePieces::rows rows per rank. After each piece the ranks
// agree whether to go on (Progress), so that no rank enters a collective write the others have
// abandoned; returns true if abandoned.
bool write_particles(WriteStatus& status, hid_t file, const particles::ParticleSet& particles,
                     const std::vector<DerivedTensor>& derived, const std::string& material_names,
                     const parallel::Communicator& comm, hsize_t start, hsize_t total, Progress& progress) {
  const hid_t group = H5Gcreate2(file, "particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  status.check(group, "create /particles");
  const auto rows = static_cast<hsize_t>(particles.size());
  const auto piece_rows = static_cast<hsize_t>(std::max<std::int64_t>(progress.pieces.rows, 1));
  const auto pieces = static_cast<hsize_t>(std::max<std::int64_t>(
      comm.max(static_cast<std::int64_t>((rows + piece_rows - 1) / piece_rows)), 1));
  const auto go_on = [&] { return progress.go_on(); };
  progress.go_on();
  std::vector<double> buffer;
  particles.for_each_field([&](const char* name, const auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    if (progress.abandoned) return;
    write_pieces(status, group, name, memory_type<T>(), row_shape<T>(), rows, start, total, piece_rows, pieces,
                 [&](hsize_t first, hsize_t count) { return field_rows(field, first, count, buffer); }, go_on);
  });
  for (const auto& d : derived) {
    if (progress.abandoned) break;
    write_pieces(status, group, d.name, H5T_NATIVE_DOUBLE, {3, 3}, rows, start, total, piece_rows, pieces,
                 [&](hsize_t first, hsize_t count) {
                   std::vector<Mat3> values(count);
                   for (hsize_t p = 0; p < count; ++p) values[p] = d.value(first + p);
                   buffer = flatten(values);
                   return static_cast<const void*>(buffer.data());
                 },
                 go_on);
  }
  write_string_attribute(status, group, "material_names", material_names);
  status.check(H5Gclose(group), "close /particles");
  return progress.abandoned;
}

// The tables, rows from rank 0 (collective creation); a table of one column is a vector (m), of
// several a matrix (m, columns).
void write_tables(WriteStatus& status, hid_t file, const std::vector<Table>& tables, const parallel::Communicator& comm,
                  bool abandoned) {
  for (const Table& table : tables) {
    if (abandoned) break;
    const auto slash = table.path.rfind('/');
    hid_t parent = file;
    if (slash != std::string::npos) {
      const std::string group_name = table.path.substr(0, slash);
      parent = H5Lexists(file, group_name.c_str(), H5P_DEFAULT) > 0
                   ? H5Gopen2(file, group_name.c_str(), H5P_DEFAULT)
                   : H5Gcreate2(file, group_name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
      status.check(parent, "create /" + group_name);
    }
    const std::string name = slash == std::string::npos ? table.path : table.path.substr(slash + 1);
    const std::size_t size = table.integers.empty() ? table.reals.size() : table.integers.size();
    const hsize_t rows_total = size / table.columns, rows_here = comm.is_root() ? rows_total : 0;
    const std::vector<hsize_t> shape = table.columns == 1 ? std::vector<hsize_t>{} : std::vector<hsize_t>{table.columns};
    if (table.integers.empty())
      write_rows(status, parent, name, H5T_NATIVE_DOUBLE, table.reals, shape, rows_here, 0, rows_total);
    else
      write_rows(status, parent, name, H5T_NATIVE_INT64, table.integers, shape, rows_here, 0, rows_total);
    if (parent != file && parent >= 0) H5Gclose(parent);
    abandoned = comm.any(!status.failed.empty());
  }
}
}  // namespace

std::int64_t write_particle_file(const std::string& path, const FileAttributes& attributes,
                                 const particles::ParticleSet& particles, const std::vector<DerivedTensor>& derived,
                                 const std::string& material_names, const parallel::Communicator& comm,
                                 const std::vector<Table>& tables, const WritePieces& pieces) {
  const std::string temporary = path + ".tmp";
  const auto n_local = static_cast<long long>(particles.size());
  long long offset = 0, n_total = 0;
  MPI_Exscan(&n_local, &offset, 1, MPI_LONG_LONG, MPI_SUM, comm.comm());
  if (comm.rank() == 0) offset = 0;
  MPI_Allreduce(&n_local, &n_total, 1, MPI_LONG_LONG, MPI_SUM, comm.comm());

  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // failures become one message, not HDF5's stack
  WriteStatus status;
  const hid_t access = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_fapl_mpio(access, comm.comm(), MPI_INFO_NULL);
  const hid_t file = H5Fcreate(temporary.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access);
  H5Pclose(access);
  // Creating the file is collective and fails on every rank alike.
  if (comm.any(file < 0)) throw SimulationError("cannot create " + temporary + ": " + write_failure_reason(temporary));
  for (const auto& [name, value] : attributes.reals) write_scalar_attribute(status, file, name, H5T_NATIVE_DOUBLE, value);
  for (const auto& [name, value] : attributes.integers) write_scalar_attribute(status, file, name, H5T_NATIVE_INT64, value);
  for (const auto& [name, value] : attributes.strings) write_string_attribute(status, file, name, value);
  for (const auto& [name, values] : attributes.real_arrays)
    write_rows(status, file, name, H5T_NATIVE_DOUBLE, values, {}, comm.is_root() ? values.size() : 0, 0, values.size());
  Progress progress{comm, pieces, status};
  const bool abandoned = write_particles(status, file, particles, derived, material_names, comm,
                                         static_cast<hsize_t>(offset), static_cast<hsize_t>(n_total), progress);
  write_tables(status, file, tables, comm, abandoned);
  status.check(H5Fclose(file), "close");
  // A stop asked for between pieces (and no failure): the partial file goes, every rank stops.
  if (progress.stop_signal != 0 && !comm.any(!status.failed.empty())) {
    if (comm.is_root()) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
    }
    comm.barrier();
    throw StopRequested(progress.stop_signal);
  }
  // Every rank learns whether any failed; the file becomes visible only when complete.
  std::string failure;
  if (comm.any(!status.failed.empty())) {
    failure = status.failed.empty() ? "failed on another rank" : status.failed;
  } else if (comm.is_root()) {
    std::error_code error;
    std::filesystem::rename(temporary, path, error);
    if (error) failure = "rename to " + path + ": " + error.message();
  }
  if (comm.any(!failure.empty())) {
    if (comm.is_root()) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
    }
    throw SimulationError("cannot write " + path + " (" + (failure.empty() ? "failed on rank 0" : failure) +
                          "): " + write_failure_reason(temporary));
  }
  return n_total;
}

std::string write_failure_reason(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path directory = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  std::error_code error;
  if (!fs::exists(directory, error)) return "the directory " + directory.string() + " does not exist (any more)";
  if (!fs::is_directory(directory, error)) return directory.string() + " is not a directory";
  if (::access(directory.c_str(), W_OK) != 0) return "the directory " + directory.string() + " is not writable";
  const fs::space_info space = fs::space(directory, error);
  if (!error && space.available < (std::uintmax_t(1) << 20))
    return "the disk is full (" + std::to_string(space.available / 1024) + " KiB free)";
  return "a write failed (disk full, a file-size limit or an I/O error)";
}

FileAttributes read_file_attributes(const std::string& path, std::int64_t& particle_count) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) throw InputError(path + ": not a readable HDF5 file");
  FileAttributes attributes;
  H5Aiterate2(file, H5_INDEX_NAME, H5_ITER_NATIVE, nullptr, collect_attribute, &attributes);
  particle_count = 0;
  const hid_t dataset = H5Dopen2(file, "particles/id", H5P_DEFAULT);
  if (dataset >= 0) {
    hsize_t n = 0;
    const hid_t space = H5Dget_space(dataset);
    H5Sget_simple_extent_dims(space, &n, nullptr);
    particle_count = static_cast<std::int64_t>(n);
    H5Sclose(space);
    H5Dclose(dataset);
  }
  H5Fclose(file);
  return attributes;
}

particles::ParticleSet read_particle_file(const std::string& path, const parallel::Communicator& comm,
                                          FileAttributes& attributes) {
  if (!std::filesystem::exists(path)) throw InputError(path + ": cannot open file");
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become our messages
  const hid_t access = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_fapl_mpio(access, comm.comm(), MPI_INFO_NULL);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, access);
  H5Pclose(access);
  if (file < 0) throw InputError(path + ": not a readable HDF5 file");
  H5Aiterate2(file, H5_INDEX_NAME, H5_ITER_NATIVE, nullptr, collect_attribute, &attributes);
  // Small root arrays: every rank reads all of each.
  for (const char* name : {"decomposition_boxes", "emitter_layers"}) {
    if (H5Lexists(file, name, H5P_DEFAULT) <= 0) continue;
    const hid_t dataset = H5Dopen2(file, name, H5P_DEFAULT);
    const hid_t space = H5Dget_space(dataset);
    hsize_t n = 0;
    H5Sget_simple_extent_dims(space, &n, nullptr);
    H5Sclose(space);
    H5Dclose(dataset);
    std::vector<double> values;
    read_rows(file, name, H5T_NATIVE_DOUBLE, values, {}, n, 0);
    attributes.real_arrays[name] = values;
  }
  const hid_t group = H5Gopen2(file, "particles", H5P_DEFAULT);
  if (group < 0) {
    H5Fclose(file);
    throw InputError(path + ": no /particles group");
  }
  H5Aiterate2(group, H5_INDEX_NAME, H5_ITER_NATIVE, nullptr, collect_attribute, &attributes);
  hsize_t n_total = 0;
  {
    const hid_t dataset = H5Dopen2(group, "id", H5P_DEFAULT);
    if (dataset < 0) {
      H5Gclose(group);
      H5Fclose(file);
      throw InputError(path + ": no /particles/id dataset");
    }
    const hid_t space = H5Dget_space(dataset);
    H5Sget_simple_extent_dims(space, &n_total, nullptr);
    H5Sclose(space);
    H5Dclose(dataset);
  }
  const auto ranks = static_cast<hsize_t>(comm.size()), rank = static_cast<hsize_t>(comm.rank());
  const hsize_t first = n_total * rank / ranks, last = n_total * (rank + 1) / ranks;
  particles::ParticleSet particles;
  particles.resize(last - first);
  std::string missing;
  particles.for_each_field([&](const char* name, auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    if constexpr (std::is_same_v<T, Vec3> || std::is_same_v<T, Mat3>) {
      std::vector<double> flat;
      if (!read_rows(group, name, H5T_NATIVE_DOUBLE, flat, row_shape<T>(), last - first, first)) missing = name;
      else unflatten(flat, field);
    } else {
      if (!read_rows(group, name, memory_type<T>(), field, {}, last - first, first)) missing = name;
    }
  });
  H5Gclose(group);
  H5Fclose(file);
  if (!missing.empty()) throw InputError(path + ": no readable /particles/" + missing + " dataset");
  return particles;
}

}  // namespace viscompm::io
