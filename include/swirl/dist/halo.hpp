// Halo: the ghost particles one rank needs from the others for the SPH grid
// passes (docs/design/mpi.md, "SPH across ranks"; issue 19 item 3).
//
// Setting. The particles are in the cell key frame of the one-rank order
// (spatial/particle_order.hpp): global_key_frame() computes it from the
// global bounding box (an exact min/max over the ranks), so it is the frame,
// and keys_in_frame() the keys, that one rank would compute for all the
// particles. After distribute_in_key_order() (dist/key_order.hpp) rank r holds
// the contiguous range [first_r, first_r + n_r) of the global order, sorted by
// key, and owns the key range [cut[r-1], cut[r]). The frame's cells have side
// at least h + skin (spatial::SortedCellGrid::cell_length_for), and a grid
// pass over particle i scans the 27 cells around i's cell.
//
// The ghosts of rank r (find()):
//  - every particle of another rank whose cell is one of the 27 cells around a
//    cell that holds a particle of r: whole cells, not only the particles
//    within h of r's, and exactly the cells SortedCellGrid scans (its loops,
//    clipped to the frame's cells); a superset of the particles within h + skin
//    of r's particles, which the tests check against a brute-force search;
//  - the global last `tail` particles that r does not own (see below).
// Found from cell keys alone, in one request round: r lists, for every other
// rank, the neighbour cells whose key range meets that rank's key range (every
// rank knows the cuts) and sends the sorted lists (all_to_all); each rank
// answers with its particles in those cells, in its memory order.
//
// insert() (exchange 1) sends the chosen fields of those particles (every
// field by default; the id, the key and the global index always) and puts
// them into the rank's ParticleSet at their global index:
//   [ghosts of ranks < r][r's own particles][ghosts of ranks > r],
// each group in global order, so the local array is the global order with
// gaps. refresh() (exchange 2, after the density pass: density, pressure)
// sends chosen fields of the same ghosts again into the same slots; remove()
// takes the ghosts out and leaves the own particles as before insert().
//
// Invariants after insert():
//  - global_index() is strictly increasing (checked) and owned() is the own
//    particles' range: global_index()[owned().begin + i] = first_r + i;
//  - every cell around a cell of an own particle is complete and contiguous:
//    its particles are those of the one-rank order, in that order. A grid view
//    of the local array with the global indices (SortedCellGrid::view(frame,
//    keys, global_index())) then hands a pass over an own particle the
//    one-rank neighbour ranges with the same particles in the same order
//    (Morton ranges are merged only where they are contiguous globally);
//  - with tail = (widest SIMD batch − 1): the explicit-SIMD passes sum each
//    range in batches from its first particle and switch to one pair at a time
//    where a full batch would read past the array's end, so a sum depends on
//    how many particles follow its range, up to the batch width − 1. With the
//    global last `tail` particles on every rank, the local array holds after
//    any range at least `tail` particles when the global order does, and
//    exactly the global ones otherwise: the same batches, the same bits.
//
// Everything is exact and ordered (sorted lists, rank-order concatenation):
// the ghost set and the local array do not depend on message timing or on the
// thread count. Units: the positions' (m for SPH); traffic in bytes.
// One rank (or no MPI): no ghosts (plus nothing: the tail is the rank's own).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "swirl/core/index_range.hpp"
#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"
#include "swirl/spatial/particle_order.hpp"

namespace swirl::dist {

// The frame ParticleOrder::update() would give all the ranks' particles under
// `request`: the global box (each rank's exact min/max, ParticleOrder's
// vectorised pass over blocks of block_size, then the min/max over ranks),
// then ParticleOrder::frame_for. cells_fit as there. Collective; throws
// spatial::NonFinitePosition on every rank when any rank holds a non-finite position.
template <class Real>
spatial::KeyFrame global_key_frame(const Communicator& comm, const ParticleSet<Real>& p,
                                   const spatial::OrderRequest& request, bool& cells_fit,
                                   std::size_t block_size = 4096) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const auto mine = spatial::ParticleOrder<Real>::local_bounds(p.size(), block_size, p.position.x.data(),
                                                              p.position.y.data(), p.position.z.data());
  std::array<double, 3> lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  if (!p.empty()) lo = mine.lo, hi = mine.hi;
  std::uint64_t counts[2] = {p.size(), mine.finite ? 0u : 1u};  // particles, ranks with a non-finite position
  comm.sum(counts);
  if (counts[1] != 0) throw spatial::NonFinitePosition();
  comm.min(lo);
  comm.max(hi);
  if (counts[0] == 0) lo = hi = {0, 0, 0};
  return spatial::ParticleOrder<Real>::frame_for(request, lo, hi, cells_fit);
}

// Every particle's key in frame f (ParticleOrder::key_of of its position).
// keys: reused (a step's sort refills the buffer of the last).
template <class Real>
void keys_in_frame(const spatial::KeyFrame& f, const ParticleSet<Real>& p, std::vector<std::uint64_t>& keys) {
  keys.resize(p.size());
  for (std::size_t i = 0; i < keys.size(); ++i)
    keys[i] = spatial::ParticleOrder<Real>::key_of(f, double(p.position.x[i]), double(p.position.y[i]),
                                                   double(p.position.z[i]));
}
template <class Real>
std::vector<std::uint64_t> keys_in_frame(const spatial::KeyFrame& f, const ParticleSet<Real>& p) {
  std::vector<std::uint64_t> keys;
  keys_in_frame(f, p, keys);
  return keys;
}

class Halo {
 public:
  Halo() = default;

  // Collective. keys: this rank's particles' keys in `frame` (a cell frame),
  // sorted (as distribute_in_key_order leaves them); first_global_index and
  // global_count: its Distribution; cut_keys: the size()-1 cuts it used; tail:
  // the global last particles every rank takes as ghosts (0: none).
  static Halo find(const Communicator& comm, const spatial::KeyFrame& frame, std::span<const std::uint64_t> keys,
                   std::uint64_t first_global_index, std::uint64_t global_count,
                   std::span<const std::uint64_t> cut_keys, std::size_t tail = 0);

  // Exchange 1 (collective): the ghosts' fields into p and their keys into
  // keys, at their global index (header). fields: names of real or integer
  // fields ("position", "velocity", "mass", an extra field, ...); empty: every
  // field. Fields not sent are zero for the ghosts. p and keys must be the
  // particles and keys find() saw, in the same order.
  template <class Real>
  void insert(const Communicator& comm, ParticleSet<Real>& p, std::vector<std::uint64_t>& keys,
              const std::vector<std::string>& fields = {});

  // Exchange 2 (collective): the named fields of the ghosts again, from their
  // owners' current values (e.g. density and pressure after the density pass).
  template <class Real>
  void refresh(const Communicator& comm, ParticleSet<Real>& p, const std::vector<std::string>& fields);

  // Takes the ghosts out: p and keys hold the own particles as before insert().
  // The halo stays valid for another insert() while the particles keep their order.
  template <class Real>
  void remove(ParticleSet<Real>& p, std::vector<std::uint64_t>& keys);

  bool inserted() const { return inserted_; }
  // The own particles in the local array (all of it when no ghosts are in).
  IndexRange owned() const { return owned_; }
  // Global index of every particle of the local array (after insert()).
  std::span<const std::uint64_t> global_index() const { return global_index_; }
  std::size_t owned_count() const { return owned_count_; }
  // Ghosts this rank receives (known after insert()), and from each rank.
  std::size_t ghost_count() const { return ghost_count_; }
  const std::vector<std::size_t>& received_from() const { return recv_count_; }
  // For every rank, the own particles (indices among the own ones, increasing) it gets as ghosts.
  const std::vector<std::vector<std::uint32_t>>& sent_to() const { return send_; }
  // What this rank sent in the last request round, insert() and refresh().
  Traffic request_traffic() const { return request_traffic_; }
  Traffic insert_traffic() const { return insert_traffic_; }
  Traffic refresh_traffic() const { return refresh_traffic_; }

 private:
  // The arrays named by `fields` (every array when empty), in a fixed order.
  template <class Real>
  struct Selection {
    std::vector<AlignedVector<Real>*> reals;
    std::vector<AlignedVector<typename ParticleSet<Real>::int_type>*> ints;
    std::size_t bytes() const {
      return reals.size() * sizeof(Real) + ints.size() * sizeof(typename ParticleSet<Real>::int_type);
    }
  };
  template <class Real>
  static Selection<Real> select(ParticleSet<Real>& p, const std::vector<std::string>& fields);

  static Traffic traffic_of(const std::vector<Bytes>& send, int self);

  int rank_ = 0;
  std::uint64_t first_ = 0;
  std::size_t owned_count_ = 0;
  std::size_t ghost_count_ = 0;
  bool inserted_ = false;
  IndexRange owned_{};
  std::vector<std::vector<std::uint32_t>> send_;  // per destination rank
  std::vector<std::size_t> recv_count_;           // per source rank (after insert)
  std::vector<std::uint64_t> global_index_;
  Traffic request_traffic_, insert_traffic_, refresh_traffic_;
};

// ---- templates ----

template <class Real>
Halo::Selection<Real> Halo::select(ParticleSet<Real>& p, const std::vector<std::string>& fields) {
  Selection<Real> s;
  if (fields.empty()) {
    p.for_each_array([&](AlignedVector<Real>& a) { s.reals.push_back(&a); });
    p.for_each_int_array([&](AlignedVector<typename ParticleSet<Real>::int_type>& a) { s.ints.push_back(&a); });
    return s;
  }
  for (const std::string& name : fields) {
    auto vec = [&](Vec3Array<Real>& v) {
      for (int a = 0; a < 3; ++a) s.reals.push_back(&v[a]);
    };
    if (name == "id") continue;  // always sent
    if (name == "position") {
      vec(p.position);
    } else if (name == "velocity") {
      vec(p.velocity);
    } else if (name == "acceleration") {
      vec(p.acceleration);
    } else if (name == "acceleration_prev") {
      vec(p.acceleration_prev);
    } else if (name == "mass") {
      s.reals.push_back(&p.mass);
    } else if (name == "density") {
      s.reals.push_back(&p.density);
    } else if (name == "pressure") {
      s.reals.push_back(&p.pressure);
    } else if (const std::size_t k = p.find_field(name); k != ParticleSet<Real>::npos) {
      int components = 1;
      for (const auto& f : p.fields())
        if (f.name == name) components = f.components;
      for (int c = 0; c < components; ++c) s.reals.push_back(&p.extra(k, c));
    } else if (const std::size_t j = p.find_int_field(name); j != ParticleSet<Real>::npos) {
      s.ints.push_back(&p.int_field(j));
    } else {
      throw std::invalid_argument("halo: no particle field named '" + name + "'");
    }
  }
  return s;
}

template <class Real>
void Halo::insert(const Communicator& comm, ParticleSet<Real>& p, std::vector<std::uint64_t>& keys,
                  const std::vector<std::string>& fields) {
  if (inserted_) throw std::logic_error("halo: the ghosts are in already");
  const std::size_t n = p.size();
  if (n != owned_count_ || keys.size() != n)
    throw std::invalid_argument("halo: insert() needs the particles and keys find() saw");
  const Selection<Real> sel = select(p, fields);
  const std::size_t record = 3 * sizeof(std::uint64_t) + sel.bytes();
  const auto ranks = static_cast<std::size_t>(comm.size());
  std::vector<Bytes> send(ranks);
  auto put = [](std::byte*& at, const auto& value) {
    std::memcpy(at, &value, sizeof(value));
    at += sizeof(value);
  };
  for (std::size_t d = 0; d < ranks; ++d) {
    send[d].resize(send_[d].size() * record);
    std::byte* at = send[d].data();
    for (const std::uint32_t i : send_[d]) {
      put(at, keys[i]);
      put(at, std::uint64_t{first_ + i});
      put(at, p.id[i]);
      for (const auto* a : sel.reals) put(at, (*a)[i]);
      for (const auto* a : sel.ints) put(at, (*a)[i]);
    }
  }
  insert_traffic_ = traffic_of(send, rank_);
  const std::vector<Bytes> received = comm.all_to_all(send);
  send.clear();

  recv_count_.assign(ranks, 0);
  std::size_t before = 0, ghosts = 0;
  for (std::size_t s = 0; s < ranks; ++s) {
    if (received[s].size() % record != 0 || (static_cast<int>(s) == rank_ && !received[s].empty()))
      throw std::runtime_error("halo: a rank sent a partial or unexpected ghost record");
    recv_count_[s] = received[s].size() / record;
    ghosts += recv_count_[s];
    if (static_cast<int>(s) < rank_) before += recv_count_[s];
  }
  const std::size_t m = n + ghosts;
  // The own particles move to [before, before + n); every ghost slot starts at zero.
  auto make_room = [&](auto& a) {
    using T = typename std::decay_t<decltype(a)>::value_type;
    // A little headroom, exactly: resize()'s growth would double every field's
    // capacity, and the ghosts are a few per cent of the particles.
    if (a.capacity() < m) a.reserve(m + m / 32);
    a.resize(m);
    std::copy_backward(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(n),
                       a.begin() + static_cast<std::ptrdiff_t>(before + n));
    std::fill(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(before), T{});
    std::fill(a.begin() + static_cast<std::ptrdiff_t>(before + n), a.end(), T{});
  };
  p.for_each_array(make_room);
  p.for_each_int_array(make_room);
  make_room(p.id);
  make_room(keys);
  global_index_.resize(m);
  for (std::size_t i = 0; i < n; ++i) global_index_[before + i] = first_ + i;

  auto get = [](const std::byte*& at, auto& value) {
    std::memcpy(&value, at, sizeof(value));
    at += sizeof(value);
  };
  std::size_t slot = 0;
  for (std::size_t s = 0; s < ranks; ++s) {
    if (static_cast<int>(s) == rank_) {
      slot += n;
      continue;
    }
    for (const std::byte* at = received[s].data(); at != received[s].data() + received[s].size(); ++slot) {
      get(at, keys[slot]);
      get(at, global_index_[slot]);
      get(at, p.id[slot]);
      for (auto* a : sel.reals) get(at, (*a)[slot]);
      for (auto* a : sel.ints) get(at, (*a)[slot]);
    }
  }
  for (std::size_t i = 1; i < m; ++i)
    if (!(global_index_[i - 1] < global_index_[i]))
      throw std::runtime_error("halo: the ghosts are not in global order (ranks disagree on the cuts?)");
  ghost_count_ = ghosts;
  owned_ = {static_cast<std::uint32_t>(before), static_cast<std::uint32_t>(before + n)};
  inserted_ = true;
}

template <class Real>
void Halo::refresh(const Communicator& comm, ParticleSet<Real>& p, const std::vector<std::string>& fields) {
  if (!inserted_ || p.size() != global_index_.size())
    throw std::logic_error("halo: refresh() needs the ghosts inserted");
  if (fields.empty()) throw std::invalid_argument("halo: refresh() needs the fields to send");
  const Selection<Real> sel = select(p, fields);
  const std::size_t record = sel.bytes();
  const auto ranks = static_cast<std::size_t>(comm.size());
  std::vector<Bytes> send(ranks);
  for (std::size_t d = 0; d < ranks; ++d) {
    send[d].resize(send_[d].size() * record);
    std::byte* at = send[d].data();
    for (const std::uint32_t own : send_[d]) {
      const std::size_t i = owned_.begin + own;
      for (const auto* a : sel.reals) {
        std::memcpy(at, &(*a)[i], sizeof(Real));
        at += sizeof(Real);
      }
      for (const auto* a : sel.ints) {
        std::memcpy(at, &(*a)[i], sizeof((*a)[i]));
        at += sizeof((*a)[i]);
      }
    }
  }
  refresh_traffic_ = traffic_of(send, rank_);
  const std::vector<Bytes> received = comm.all_to_all(send);
  std::size_t slot = 0;
  for (std::size_t s = 0; s < ranks; ++s) {
    if (static_cast<int>(s) == rank_) {
      slot += owned_count_;
      continue;
    }
    if (received[s].size() != recv_count_[s] * record)
      throw std::runtime_error("halo: a rank refreshed another number of ghosts");
    for (const std::byte* at = received[s].data(); at != received[s].data() + received[s].size(); ++slot) {
      for (auto* a : sel.reals) {
        std::memcpy(&(*a)[slot], at, sizeof(Real));
        at += sizeof(Real);
      }
      for (auto* a : sel.ints) {
        std::memcpy(&(*a)[slot], at, sizeof((*a)[slot]));
        at += sizeof((*a)[slot]);
      }
    }
  }
}

template <class Real>
void Halo::remove(ParticleSet<Real>& p, std::vector<std::uint64_t>& keys) {
  if (!inserted_) return;
  if (p.size() != global_index_.size() || keys.size() != p.size())
    throw std::invalid_argument("halo: remove() needs the particles and keys insert() left");
  const std::size_t b = owned_.begin, n = owned_count_;
  auto take_own = [&](auto& a) {
    std::copy(a.begin() + static_cast<std::ptrdiff_t>(b), a.begin() + static_cast<std::ptrdiff_t>(b + n), a.begin());
    a.resize(n);
  };
  p.for_each_array(take_own);
  p.for_each_int_array(take_own);
  take_own(p.id);
  take_own(keys);
  global_index_.clear();
  owned_ = {0, static_cast<std::uint32_t>(n)};
  ghost_count_ = 0;
  inserted_ = false;
}

}  // namespace swirl::dist
