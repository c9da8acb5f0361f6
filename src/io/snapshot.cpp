// HDF5 snapshots in the Gadget-format layout (io/snapshot.hpp), through the
// HDF5 C library: written into an in-memory file (the core driver, no backing
// store) whose image then goes to disk atomically, or by several processes
// into one file through parallel HDF5 (MPI-IO: write_snapshot_part); read
// with every group, dataset and attribute checked before it is used.
#include "swirl/io/snapshot.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <type_traits>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "detail.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/read_file.hpp"
#include "swirl/io/write_faults.hpp"

#if SWIRL_PARALLEL_HDF5
#include <mpi.h>  // parallel HDF5's MPI-IO driver (builds with MPI: cmake/hdf5.cmake)
#endif

namespace swirl::io {
namespace {

namespace fs = std::filesystem;

constexpr int kTypes = kGadgetTypes;         // Gadget's particle types
constexpr hsize_t kChunkRows = 1 << 16;      // rows per chunk
constexpr unsigned kDeflateLevel = 1;

// Owns one HDF5 identifier and closes it with the matching function.
class Id {
 public:
  Id() = default;
  Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  Id(Id&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), close_(o.close_) {}
  Id& operator=(Id&& o) noexcept {
    std::swap(id_, o.id_);
    std::swap(close_, o.close_);
    return *this;
  }
  ~Id() {
    if (id_ >= 0 && close_) close_(id_);
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  hid_t release() { return std::exchange(id_, H5I_INVALID_HID); }

 private:
  hid_t id_ = H5I_INVALID_HID;
  herr_t (*close_)(hid_t) = nullptr;
};

// HDF5 prints its own error stack by default; swirl reports errors itself.
void silence_hdf5() {
  static const bool silenced = [] { return H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr) >= 0; }();
  (void)silenced;
}

// ---- writing -----------------------------------------------------------------

// The dataset write a test asked to fail (io/write_faults.hpp).
detail::InjectedFault injected_write_fault;

struct Writer {
  fs::path path;  // the file asked for (errors name it, not a temporary one)
  Id file;
  SnapshotLayout layout;
  // This process writes rows [first, first + mine) of every dataset's total:
  // all of them alone; on several ranks (parallel HDF5) its part, with the
  // collective transfer properties `transfer`.
  hsize_t first = 0, mine = 0, total = 0;
  Id transfer;

  [[noreturn]] void fail(std::string_view what) const {
    throw IoError(fmt::format("{}: writing {} failed (HDF5)", path.string(), what));
  }
  hid_t check(hid_t id, std::string_view what) const {
    if (id < 0) fail(what);
    return id;
  }
  void check(herr_t status, std::string_view what, int) const {
    if (status < 0) fail(what);
  }

  Id group(hid_t parent, const char* name) const {
    Id gcpl(check(H5Pcreate(H5P_GROUP_CREATE), name), H5Pclose);
    check(H5Pset_obj_track_times(gcpl.get(), false), name, 0);
    return Id(check(H5Gcreate2(parent, name, H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), name), H5Gclose);
  }

  template <class T>
  void attribute(hid_t owner, const char* name, hid_t type, const T* values, hsize_t count) const {
    Id space(check(count == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &count, nullptr), name), H5Sclose);
    Id attr(check(H5Acreate2(owner, name, type, space.get(), H5P_DEFAULT, H5P_DEFAULT), name), H5Aclose);
    check(H5Awrite(attr.get(), type, values), name, 0);
  }
  void attribute(hid_t owner, const char* name, double value) const {
    attribute(owner, name, H5T_NATIVE_DOUBLE, &value, 1);
  }
  void attribute(hid_t owner, const char* name, std::int32_t value) const {
    attribute(owner, name, H5T_NATIVE_INT32, &value, 1);
  }
  void attribute(hid_t owner, const char* name, std::string_view text) const {
    Id type(check(H5Tcopy(H5T_C_S1), name), H5Tclose);
    check(H5Tset_size(type.get(), std::max<std::size_t>(1, text.size())), name, 0);
    check(H5Tset_strpad(type.get(), H5T_STR_NULLPAD), name, 0);
    std::string padded(text);
    padded.resize(std::max<std::size_t>(1, text.size()), '\0');
    attribute(owner, name, type.get(), padded.data(), 1);
  }

  // Creates a dataset of total × `columns` values of `type` (with its units
  // attribute) and queues the write of this process's rows [first, first +
  // mine) of it, filled from `fill(row, column)` (row counted from this
  // process's first), for write_queued().
  template <class T, class Fill>
  void dataset(hid_t group, const std::string& name, hid_t type, int columns, std::string_view units, Fill fill) {
    layout.datasets.push_back({name, columns, std::is_integral_v<T>, std::is_unsigned_v<T>, int(sizeof(T))});
    const hsize_t dims[2] = {total, hsize_t(columns)};
    const int rank = columns == 1 ? 1 : 2;
    Id space(check(H5Screate_simple(rank, dims, nullptr), name), H5Sclose);
    Id dcpl(check(H5Pcreate(H5P_DATASET_CREATE), name), H5Pclose);
    check(H5Pset_obj_track_times(dcpl.get(), false), name, 0);
    if (total > 0) {
      const hsize_t chunk[2] = {std::min<hsize_t>(total, kChunkRows), hsize_t(columns)};
      check(H5Pset_chunk(dcpl.get(), rank, chunk), name, 0);
      check(H5Pset_shuffle(dcpl.get()), name, 0);
      check(H5Pset_deflate(dcpl.get(), kDeflateLevel), name, 0);
      // Every chunk's space at creation, as parallel HDF5 allocates it.
      check(H5Pset_alloc_time(dcpl.get(), H5D_ALLOC_TIME_EARLY), name, 0);
    }
    auto set = std::make_shared<Id>(
        check(H5Dcreate2(group, name.c_str(), type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT), name),
        H5Dclose);
    if (!units.empty()) attribute(set->get(), "units", units);
    if (total == 0) return;
    queued.push_back([this, set, name, type, rank, columns, fill] {
      std::vector<T> values(std::max<hsize_t>(mine, 1) * std::size_t(columns));
      for (std::size_t i = 0; i < mine; ++i)
        for (int c = 0; c < columns; ++c) values[i * std::size_t(columns) + std::size_t(c)] = fill(i, c);
      if (!transfer.valid()) {
        const herr_t status = H5Dwrite(set->get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
        check(injected_write_fault.now() ? herr_t(-1) : status, name, 0);
        return;
      }
      // This rank's hyperslab, collectively (a rank without rows selects none).
      Id file_space(check(H5Dget_space(set->get()), name), H5Sclose);
      const hsize_t start[2] = {first, 0}, count[2] = {std::max<hsize_t>(mine, 1), hsize_t(columns)};
      Id memory(check(H5Screate_simple(rank, count, nullptr), name), H5Sclose);
      if (mine > 0) {
        check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr), name, 0);
      } else {
        check(H5Sselect_none(file_space.get()), name, 0);
        check(H5Sselect_none(memory.get()), name, 0);
      }
      const herr_t status = H5Dwrite(set->get(), type, memory.get(), file_space.get(), transfer.get(), values.data());
      check(injected_write_fault.now() ? herr_t(-1) : status, name, 0);
    });
  }

  // Writes the queued datasets' values, once every group, dataset and
  // attribute exists. Why: the file's layout must not depend on the number of
  // processes writing it, and the compressed chunks take their places among
  // the free space that creating the metadata leaves (a group's heap that
  // grows, an early allocation given back), which parallel HDF5 and one
  // process reach in different orders when datasets are created between
  // writes (measured with HDF5 1.10.8: a rank holding two chunks alone then
  // gave another file; with every object created first, and one process
  // writing without a chunk cache, the core driver and MPI-IO on 1-4 ranks
  // give the same bytes: tests/dist/snapshot_on_ranks_test.cpp).
  //
  // Every queued write runs even after one has failed, and the first failure
  // is thrown after the last: on several ranks each write is a collective
  // call, and a rank that stopped at its own failure would leave the others
  // waiting in the next one (they learn of the failure when the ranks agree
  // on the outcome, dist/snapshot_on_ranks.cpp).
  void write_queued() {
    std::exception_ptr first_failure;
    for (auto& write : queued) {
      try {
        write();
      } catch (const IoError&) {
        if (!first_failure) first_failure = std::current_exception();
      }
    }
    queued.clear();
    if (first_failure) std::rethrow_exception(first_failure);
  }
  std::vector<std::function<void()>> queued;
};

template <class Real>
hid_t native_real() {
  return sizeof(Real) == sizeof(double) ? H5T_NATIVE_DOUBLE : H5T_NATIVE_FLOAT;
}

// The Gadget name of a built-in field and its unit in words; other fields keep their name.
std::pair<std::string, std::string_view> dataset_name(std::string_view field, bool si) {
  if (field == "position") return {"Coordinates", si ? "m" : "length"};
  if (field == "velocity") return {"Velocities", si ? "m/s" : "length/time"};
  if (field == "acceleration") return {"Accelerations", si ? "m/s^2" : "length/time^2"};
  if (field == "mass") return {"Masses", si ? "kg" : "mass"};
  if (field == "density") return {"Density", si ? "kg/m^3" : "mass/length^3"};
  if (field == "pressure") return {"Pressure", si ? "Pa" : "mass/(length time^2)"};
  if (field == "potential") return {"potential", si ? "J/kg" : "length^2/time^2"};
  return {std::string(field), ""};
}

// ---- reading -----------------------------------------------------------------

struct Reader {
  fs::path path;
  Id file;

  [[noreturn]] void fail(std::string_view where, std::string_view why) const {
    throw IoError(fmt::format("{}: {}: {}", path.string(), where, why));
  }

  bool has(hid_t parent, const char* name) const { return H5Lexists(parent, name, H5P_DEFAULT) > 0; }

  // A numeric attribute of `count` values, converted to T; nullopt when absent.
  template <class T>
  std::optional<std::vector<T>> attribute(hid_t owner, const std::string& where, const char* name, hid_t type,
                                          hsize_t count) const {
    if (H5Aexists(owner, name) <= 0) return std::nullopt;
    Id attr(H5Aopen(owner, name, H5P_DEFAULT), H5Aclose);
    if (!attr.valid()) fail(where + "/" + name, "cannot be opened");
    Id space(H5Aget_space(attr.get()), H5Sclose);
    const hssize_t n = H5Sget_simple_extent_npoints(space.get());
    if (n != hssize_t(count)) fail(where + "/" + name, fmt::format("has {} values, expected {}", n, count));
    Id stored(H5Aget_type(attr.get()), H5Tclose);
    const H5T_class_t cls = H5Tget_class(stored.get());
    if (cls != H5T_INTEGER && cls != H5T_FLOAT) fail(where + "/" + name, "is not a number");
    std::vector<T> out(count);
    if (H5Aread(attr.get(), type, out.data()) < 0) fail(where + "/" + name, "cannot be read as a number");
    return out;
  }

  // A fixed-length string attribute; empty when absent or of another kind.
  std::string text(hid_t owner, const char* name) const {
    if (H5Aexists(owner, name) <= 0) return {};
    Id attr(H5Aopen(owner, name, H5P_DEFAULT), H5Aclose);
    Id type(attr.valid() ? H5Aget_type(attr.get()) : H5I_INVALID_HID, H5Tclose);
    if (!type.valid() || H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) != 0) return {};
    const std::size_t size = H5Tget_size(type.get());
    if (size == 0 || size > 4096) return {};
    std::string out(size, '\0');
    if (H5Aread(attr.get(), type.get(), out.data()) < 0) return {};
    out.resize(std::strlen(out.c_str()));
    return out;
  }

  // A dataset opened and its shape checked: `rows` rows of 1 to 9 numbers.
  struct OpenDataset {
    Id set;
    SnapshotLayout::Dataset shape;
  };
  OpenDataset open_dataset(hid_t group, const std::string& where, const std::string& name, std::size_t rows) const {
    const std::string at = where + "/" + name;
    Id set(H5Dopen2(group, name.c_str(), H5P_DEFAULT), H5Dclose);
    if (!set.valid()) fail(at, "is not a dataset");
    Id space(H5Dget_space(set.get()), H5Sclose);
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 1 || rank > 2) fail(at, fmt::format("has {} dimensions, expected 1 or 2", rank));
    hsize_t dims[2] = {0, 1};
    H5Sget_simple_extent_dims(space.get(), dims, nullptr);
    if (rank == 1) dims[1] = 1;
    if (dims[0] != rows) fail(at, fmt::format("has {} rows, the header says {} particles", dims[0], rows));
    if (dims[1] < 1 || dims[1] > 9) fail(at, fmt::format("has {} columns, expected 1 to 9", dims[1]));
    Id type(H5Dget_type(set.get()), H5Tclose);
    const H5T_class_t cls = H5Tget_class(type.get());
    if (cls != H5T_INTEGER && cls != H5T_FLOAT) fail(at, "is not numeric");
    const bool integer = cls == H5T_INTEGER;
    return {std::move(set),
            {name, int(dims[1]), integer, integer && H5Tget_sign(type.get()) == H5T_SGN_NONE,
             int(H5Tget_size(type.get()))}};
  }

  // A dataset's values in double, every one finite.
  SnapshotDataset dataset(hid_t group, const std::string& where, const std::string& name, std::size_t rows) const {
    const std::string at = where + "/" + name;
    const OpenDataset open = open_dataset(group, where, name, rows);
    SnapshotDataset d;
    d.columns = std::size_t(open.shape.components);
    d.integer = open.shape.integer;
    d.units = text(open.set.get(), "units");
    d.values.resize(rows * d.columns);
    if (rows > 0 && H5Dread(open.set.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, d.values.data()) < 0)
      fail(at, "cannot be read (corrupt or filtered with a filter this HDF5 lacks)");
    for (std::size_t k = 0; k < d.values.size(); ++k)
      if (!std::isfinite(d.values[k]))
        fail(at, fmt::format("the value of particle {} (column {}) is not finite", k / d.columns, k % d.columns));
    return d;
  }
};

// Writes the header and the particles `rows` of p (all of them without
// rows) into w's open file, as rows [w.first, w.first + w.mine) of w.total.
template <class Real>
void write_contents(Writer& w, const ParticleSet<Real>& p, ParticleRows rows,
                    const SnapshotInfo& info) {
  w.layout.time = info.time;
  w.layout.type = info.type;
  w.layout.count = w.total;
  const hid_t root = w.file.get();
  const std::uint64_t n = w.total;
  const bool si = info.si_units;
  const auto at = [&](std::size_t i) { return rows ? (*rows)[i] : i; };

  {
    Id header = w.group(root, "Header");
    std::array<std::uint32_t, kTypes> count{}, high{};
    count[std::size_t(info.type)] = std::uint32_t(n & 0xffffffffu);
    high[std::size_t(info.type)] = std::uint32_t(n >> 32);
    const std::array<double, kTypes> mass_table{};
    w.attribute(header.get(), "NumPart_ThisFile", H5T_NATIVE_UINT32, count.data(), kTypes);
    w.attribute(header.get(), "NumPart_Total", H5T_NATIVE_UINT32, count.data(), kTypes);
    w.attribute(header.get(), "NumPart_Total_HighWord", H5T_NATIVE_UINT32, high.data(), kTypes);
    w.attribute(header.get(), "MassTable", H5T_NATIVE_DOUBLE, mass_table.data(), kTypes);
    w.attribute(header.get(), "Time", info.time);
    w.attribute(header.get(), "Redshift", 0.0);
    w.attribute(header.get(), "BoxSize", info.box_size);
    w.attribute(header.get(), "NumFilesPerSnapshot", std::int32_t(1));
    w.attribute(header.get(), "Flag_DoublePrecision", std::int32_t(sizeof(Real) == sizeof(double)));
    w.attribute(header.get(), "SwirlFormatVersion", std::int32_t(kSnapshotVersion));
    w.attribute(header.get(), "UnitSystem", std::string_view(si ? "si" : "nbody"));
    w.attribute(header.get(), "GravitationalConstant", info.gravitational_constant);
  }
  if (si) {
    Id units = w.group(root, "Units");
    w.attribute(units.get(), "Unit length in cgs (U_L)", 100.0);
    w.attribute(units.get(), "Unit mass in cgs (U_M)", 1000.0);
    w.attribute(units.get(), "Unit time in cgs (U_t)", 1.0);
    w.attribute(units.get(), "Unit current in cgs (U_I)", 1.0);
    w.attribute(units.get(), "Unit temperature in cgs (U_T)", 1.0);
  }

  Id group = w.group(root, fmt::format("PartType{}", int(info.type)).c_str());
  const hid_t real = native_real<Real>();
  // Coordinates, Velocities, Masses first (the order readers list them in), then the rest.
  const auto fields = p.fields();  // the queued writes read them (write_queued)
  const auto write_field = [&](const FieldView<const Real>& f) {
    const auto [name, units] = dataset_name(f.name, si);
    w.dataset<Real>(group.get(), name, real, f.components, units,
                    [&](std::size_t i, int c) { return f.data[std::size_t(c)][at(i)]; });
  };
  for (std::string_view first : {"position", "velocity", "mass"})
    for (const auto& f : fields)
      if (f.name == first) write_field(f);
  w.dataset<std::uint64_t>(group.get(), "ParticleIDs", H5T_NATIVE_UINT64, 1, "",
                           [&](std::size_t i, int) { return std::uint64_t(p.id[at(i)]); });
  for (const auto& f : fields)
    if (!f.internal && f.name != "position" && f.name != "velocity" && f.name != "mass") write_field(f);
  const auto int_fields = p.int_fields();  // the queued writes read them (write_queued)
  for (const auto& f : int_fields)
    if (!f.internal)
      w.dataset<std::int32_t>(group.get(), std::string(f.name), H5T_NATIVE_INT32, 1, "",
                              [&](std::size_t i, int) { return f.data[0][at(i)]; });
  w.write_queued();
}

// Closes w's file, reporting a failure (its last writes happen here).
void close_file(Writer& w) {
  if (H5Fclose(w.file.release()) < 0) w.fail("the file (closing it)");
}

template <class Real>
void check_rows(const fs::path& path, const ParticleSet<Real>& p, ParticleRows rows) {
  if (rows)
    for (const std::size_t i : *rows)
      if (i >= p.size())
        throw std::out_of_range(fmt::format("{}: write_snapshot: row {} of a set of {} particles", path.string(), i,
                                            p.size()));
}

}  // namespace

template <class Real>
SnapshotLayout write_snapshot(const fs::path& path, const ParticleSet<Real>& p, const SnapshotInfo& info,
                              ParticleRows rows) {
  silence_hdf5();
  check_rows(path, p, rows);
  Writer w;
  w.path = path;
  w.mine = w.total = rows ? rows->size() : p.size();
  Id fapl(w.check(H5Pcreate(H5P_FILE_ACCESS), "the file"), H5Pclose);
  w.check(H5Pset_fapl_core(fapl.get(), std::size_t(1) << 20, false), "the file", 0);
  // No chunk cache: each chunk is compressed and placed when it is written,
  // in chunk order, as parallel HDF5's collective writes place them (a cache
  // would place them when it evicts them: another layout).
  w.check(H5Pset_cache(fapl.get(), 0, 0, 0, 1.0), "the file (no chunk cache)", 0);
  w.file = Id(w.check(H5Fcreate(path.string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), "the file"), H5Fclose);
  write_contents(w, p, rows, info);
  const hid_t root = w.file.get();
  w.check(H5Fflush(root, H5F_SCOPE_GLOBAL), "the file", 0);
  const ssize_t size = H5Fget_file_image(root, nullptr, 0);
  if (size < 0) w.fail("the file image");
  std::string image(std::size_t(size), '\0');
  if (H5Fget_file_image(root, image.data(), std::size_t(size)) != size) w.fail("the file image");
  close_file(w);
  write_file_atomic(path, image);
  return std::move(w.layout);
}

template <class Real>
SnapshotLayout write_snapshot_part(const SnapshotPart& part, const fs::path& path_in_messages,
                                   const ParticleSet<Real>& p, const SnapshotInfo& info, ParticleRows rows) {
#if SWIRL_PARALLEL_HDF5
  silence_hdf5();
  check_rows(path_in_messages, p, rows);
  if (part.mpi_comm == nullptr) throw std::logic_error("write_snapshot_part: no MPI communicator");
  Writer w;
  w.path = path_in_messages;
  w.first = part.first;
  w.mine = rows ? rows->size() : p.size();
  w.total = part.total;
  if (w.first + w.mine > w.total) throw std::logic_error("write_snapshot_part: rows beyond the file's total");
  Id fapl(w.check(H5Pcreate(H5P_FILE_ACCESS), "the file"), H5Pclose);
  const MPI_Comm comm = *static_cast<const MPI_Comm*>(part.mpi_comm);
  w.check(H5Pset_fapl_mpio(fapl.get(), comm, MPI_INFO_NULL), "the file (MPI-IO access)", 0);
  w.transfer = Id(w.check(H5Pcreate(H5P_DATASET_XFER), "the file"), H5Pclose);
  w.check(H5Pset_dxpl_mpio(w.transfer.get(), H5FD_MPIO_COLLECTIVE), "the file (collective transfer)", 0);
  w.file = Id(w.check(H5Fcreate(part.file.string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), "the file"),
              H5Fclose);
  write_contents(w, p, rows, info);
  close_file(w);
  return std::move(w.layout);
#else
  (void)part, (void)p, (void)info, (void)rows;
  throw std::logic_error(fmt::format("{}: a snapshot written by several processes needs parallel HDF5 (a build with MPI)",
                                     path_in_messages.string()));
#endif
}

template SnapshotLayout write_snapshot<float>(const fs::path&, const ParticleSet<float>&, const SnapshotInfo&,
                                              ParticleRows);
template SnapshotLayout write_snapshot<double>(const fs::path&, const ParticleSet<double>&, const SnapshotInfo&,
                                               ParticleRows);
template SnapshotLayout write_snapshot_part<float>(const SnapshotPart&, const fs::path&, const ParticleSet<float>&,
                                                   const SnapshotInfo&, ParticleRows);
template SnapshotLayout write_snapshot_part<double>(const SnapshotPart&, const fs::path&, const ParticleSet<double>&,
                                                    const SnapshotInfo&, ParticleRows);

namespace {

// A snapshot file opened, its header's particle counts read.
struct Head {
  Reader r;
  Id header;
  std::array<std::uint64_t, kTypes> counts{};
};

Head open_head(const fs::path& path) {
  silence_hdf5();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw IoError(fmt::format("{}: not a regular file", path.string()));
  if (fs::file_size(path, ec) > max_particle_file_bytes())
    throw IoError(fmt::format("{}: larger than the {} bytes a particle file may have", path.string(),
                              max_particle_file_bytes()));
  Head h{Reader{path, {}}, {}, {}};
  Reader& r = h.r;
  if (H5Fis_hdf5(path.string().c_str()) <= 0) throw IoError(fmt::format("{}: not an HDF5 file", path.string()));
  r.file = Id(H5Fopen(path.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!r.file.valid()) throw IoError(fmt::format("{}: cannot be opened as HDF5", path.string()));
  if (!r.has(r.file.get(), "Header")) r.fail("/Header", "missing (not a Gadget-format snapshot)");
  h.header = Id(H5Gopen2(r.file.get(), "Header", H5P_DEFAULT), H5Gclose);
  if (!h.header.valid()) r.fail("/Header", "is not a group");
  const auto counts = r.attribute<std::uint64_t>(h.header.get(), "/Header", "NumPart_ThisFile", H5T_NATIVE_UINT64, kTypes);
  if (!counts) r.fail("/Header/NumPart_ThisFile", "missing");
  std::copy(counts->begin(), counts->end(), h.counts.begin());
  return h;
}

// "/PartType0, /PartType1": the particle groups a file has, for messages.
std::string part_groups(const Reader& r) {
  std::string out;
  for (int k = 0; k < kTypes; ++k)
    if (r.has(r.file.get(), fmt::format("PartType{}", k).c_str()))
      out += fmt::format("{}/PartType{}", out.empty() ? "" : ", ", k);
  return out.empty() ? std::string("no /PartType<k> group") : out;
}

// A snapshot opened and its header checked: what both readers start from.
struct Opened {
  Reader r;
  SnapshotFile head;  // info, version, count, units
  std::optional<std::vector<double>> mass_table;
  std::string where;  // "/PartType<k>"
  Id group;
  std::vector<std::string> datasets;  // the group's datasets, by name
};

Opened open_snapshot(const fs::path& path, std::optional<int> part_type) {
  Head h = open_head(path);
  Opened o{std::move(h.r), {}, std::nullopt, {}, {}, {}};
  Reader& r = o.r;
  const hid_t root = r.file.get();
  const hid_t header = h.header.get();
  const auto& counts = h.counts;
  o.mass_table = r.attribute<double>(header, "/Header", "MassTable", H5T_NATIVE_DOUBLE, kTypes);
  SnapshotFile& out = o.head;
  if (const auto t = r.attribute<double>(header, "/Header", "Time", H5T_NATIVE_DOUBLE, 1)) out.info.time = (*t)[0];
  if (const auto b = r.attribute<double>(header, "/Header", "BoxSize", H5T_NATIVE_DOUBLE, 1))
    out.info.box_size = (*b)[0];
  if (const auto v = r.attribute<int>(header, "/Header", "SwirlFormatVersion", H5T_NATIVE_INT, 1))
    out.version = (*v)[0];
  if (out.version > kSnapshotVersion)
    r.fail("/Header/SwirlFormatVersion",
           fmt::format("is {}, newer than this swirl's {}: read it with a newer swirl", out.version, kSnapshotVersion));
  out.unit_system = r.text(header, "UnitSystem");
  out.info.si_units = out.unit_system != "nbody";
  if (const auto g = r.attribute<double>(header, "/Header", "GravitationalConstant", H5T_NATIVE_DOUBLE, 1))
    out.info.gravitational_constant = (*g)[0];
  else if (!out.info.si_units)
    out.info.gravitational_constant = 1;
  if (!std::isfinite(out.info.time)) r.fail("/Header/Time", "is not finite");
  // One file of a split snapshot holds only some of the particles: read alone it would silently lose the rest.
  if (const auto files = r.attribute<std::int64_t>(header, "/Header", "NumFilesPerSnapshot", H5T_NATIVE_INT64, 1);
      files && (*files)[0] > 1)
    r.fail("/Header/NumFilesPerSnapshot",
           fmt::format("is {}: this file is one part of a snapshot split over several files, which swirl does not "
                       "read (join the parts into one file first)",
                       (*files)[0]));
  if (r.has(root, "Units")) {
    // What the file's units are, for a reader that must not take them for its own (scene sources).
    Id units(H5Gopen2(root, "Units", H5P_DEFAULT), H5Gclose);
    if (!units.valid()) r.fail("/Units", "is not a group");
    const auto factor = [&](const char* name) {
      const auto v = r.attribute<double>(units.get(), "/Units", name, H5T_NATIVE_DOUBLE, 1);
      if (!v) r.fail(fmt::format("/Units/{}", name), "missing");
      if (!((*v)[0] > 0) || !std::isfinite((*v)[0]))
        r.fail(fmt::format("/Units/{}", name), fmt::format("must be a finite number > 0, got {}", (*v)[0]));
      return (*v)[0];
    };
    out.cgs_units = CgsUnits{factor("Unit length in cgs (U_L)"), factor("Unit mass in cgs (U_M)"),
                             factor("Unit time in cgs (U_t)")};
  }

  int type = -1;
  if (part_type) {
    if (*part_type < 0 || *part_type >= kTypes)
      throw IoError(fmt::format("{}: particle type {} is not one of Gadget's 0 to {}", path.string(), *part_type,
                                kTypes - 1));
    type = *part_type;
  } else {
    for (int k = 0; k < kTypes; ++k) {
      if (counts[std::size_t(k)] == 0) continue;
      if (type >= 0)
        r.fail("/Header/NumPart_ThisFile",
               fmt::format("has particles of types {} and {}: swirl reads one particle type per file", type, k));
      type = k;
    }
    if (type < 0) type = r.has(root, "PartType1") ? 1 : 0;  // an empty snapshot
    if (type > 1)
      r.fail("/Header/NumPart_ThisFile", fmt::format("has particles of type {}: swirl reads types 0 and 1", type));
  }
  out.info.type = PartType(type);
  const std::uint64_t count = counts[std::size_t(type)];
  if (count > max_particle_file_bytes() / 24)
    r.fail("/Header/NumPart_ThisFile", fmt::format("says {} particles, more than the file can hold", count));
  out.count = std::size_t(count);

  o.where = fmt::format("/PartType{}", type);
  if (!r.has(root, o.where.c_str() + 1)) r.fail(o.where, fmt::format("missing (the file has {})", part_groups(r)));
  o.group = Id(H5Gopen2(root, o.where.c_str() + 1, H5P_DEFAULT), H5Gclose);
  if (!o.group.valid()) r.fail(o.where, "is not a group");
  std::vector<std::string> names;  // H5Literate visits the links in name order
  H5Literate(
      o.group.get(), H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* link, const H5L_info_t*, void* data) -> herr_t {
        static_cast<std::vector<std::string>*>(data)->emplace_back(link);
        return 0;
      },
      &names);
  for (auto& name : names) {
    Id object(H5Oopen(o.group.get(), name.c_str(), H5P_DEFAULT), H5Oclose);
    if (object.valid() && H5Iget_type(object.get()) == H5I_DATASET) o.datasets.push_back(std::move(name));
  }
  return o;
}

}  // namespace

std::array<std::uint64_t, kGadgetTypes> snapshot_particle_counts(const fs::path& path) {
  return open_head(path).counts;
}

SnapshotFile read_snapshot(const fs::path& path, std::optional<int> part_type) {
  Opened o = open_snapshot(path, part_type);
  const Reader& r = o.r;
  SnapshotFile out = std::move(o.head);
  const std::string& where = o.where;
  for (const auto& name : o.datasets) {
    if (name == "ParticleIDs") {  // read once, as the integers they are
      const auto ids = r.open_dataset(o.group.get(), where, name, out.count);
      if (ids.shape.components != 1 || !ids.shape.integer)
        r.fail(where + "/ParticleIDs", "must be one integer per particle");
      out.ids.resize(out.count);
      if (out.count > 0 &&
          H5Dread(ids.set.get(), H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.ids.data()) < 0)
        r.fail(where + "/ParticleIDs", "cannot be read as unsigned integers");
      continue;
    }
    out.datasets.emplace(name, r.dataset(o.group.get(), where, name, out.count));
  }
  if (out.ids.empty()) {
    out.ids.resize(out.count);
    for (std::size_t i = 0; i < out.count; ++i) out.ids[i] = i;
  }
  const auto require = [&](const char* name, std::size_t columns) {
    const auto it = out.datasets.find(name);
    if (it == out.datasets.end()) r.fail(where + "/" + name, "missing");
    if (it->second.columns != columns)
      r.fail(where + "/" + name, fmt::format("has {} columns, expected {}", it->second.columns, columns));
  };
  require("Coordinates", 3);
  if (!out.datasets.contains("Velocities")) {
    SnapshotDataset v;
    v.columns = 3;
    v.values.assign(3 * out.count, 0.0);
    out.datasets.emplace("Velocities", std::move(v));  // Gadget ICs may start at rest
  }
  require("Velocities", 3);
  if (!out.datasets.contains("Masses")) {
    const int type = int(out.info.type);
    const double m = o.mass_table ? (*o.mass_table)[std::size_t(type)] : 0.0;
    if (!(m > 0) || !std::isfinite(m))
      r.fail(where + "/Masses", fmt::format("missing, and /Header/MassTable gives no mass for type {}", type));
    SnapshotDataset masses;
    masses.values.assign(out.count, m);
    out.datasets.emplace("Masses", std::move(masses));
  }
  require("Masses", 1);
  return out;
}

SnapshotLayout read_snapshot_layout(const fs::path& path, std::optional<int> part_type) {
  Opened o = open_snapshot(path, part_type);
  SnapshotLayout layout;
  layout.time = o.head.info.time;
  layout.type = o.head.info.type;
  layout.count = o.head.count;
  for (const auto& name : o.datasets)
    layout.datasets.push_back(o.r.open_dataset(o.group.get(), o.where, name, layout.count).shape);
  return layout;
}

namespace testing {
void fail_snapshot_dataset_write(int n) { injected_write_fault.arm(n); }
}  // namespace testing

}  // namespace swirl::io
