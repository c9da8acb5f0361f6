// The whole particle set of a distributed run, and a rank's share of it.
//
// gather_to_root(): the ranks' particles concatenated in rank order on rank 0
// (every field, bit for bit; the other ranks get an empty set with the same
// fields). Under the distributed order's invariant (dist/key_order.hpp) that
// is the one-rank memory order, so a frame written from it is the one-rank
// file byte for byte. It holds every particle on rank 0 for the time of one
// write: what the VTK and CSV frames still use (HDF5 frames are written by
// every rank, dist/snapshot_on_ranks.hpp; checkpoints streamed to rank 0 one
// array at a time, dist/checkpoint_on_ranks.hpp).
//
// keep_range(): drops every particle outside [begin, end) and gives the rest
// of the memory back (a rank taking its slice of a set it holds whole).
//
// share_layout_from_root() and scatter_from_root(): the start of a run whose
// set only rank 0 built or read (so that the peak memory is one set, not one
// per rank): every rank gets rank 0's fields, then its slice of the particles.
//
// Collective where it says so. Units: whatever the fields hold.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "swirl/core/particle_set.hpp"
#include "swirl/dist/communicator.hpp"

namespace swirl::dist {

// A set without particles with p's fields, declared in p's order.
template <class Real>
ParticleSet<Real> empty_like(const ParticleSet<Real>& p) {
  ParticleSet<Real> s;
  constexpr std::size_t kBuiltIn = 7;  // position ... pressure (ParticleSet::fields())
  const auto fields = p.fields();
  for (std::size_t k = kBuiltIn; k < fields.size(); ++k)
    s.add_field(std::string(fields[k].name), fields[k].components, fields[k].internal ? FieldUse::Internal : FieldUse::Output);
  for (const auto& f : p.int_fields()) s.add_int_field(std::string(f.name), f.internal ? FieldUse::Internal : FieldUse::Output);
  return s;
}

// Collective: every rank's particles on rank 0, in rank order. `p` must have
// the same fields, declared in the same order, on every rank.
template <class Real>
ParticleSet<Real> gather_to_root(const Communicator& comm, const ParticleSet<Real>& p) {
  using Int = typename ParticleSet<Real>::int_type;
  if (!comm.distributed()) return p;
  ParticleSet<Real> whole = empty_like(p);
  std::size_t reals = 0, ints = 0;
  p.for_each_array([&](const AlignedVector<Real>&) { ++reals; });
  p.for_each_int_array([&](const AlignedVector<Int>&) { ++ints; });
  const std::size_t record = sizeof(std::uint64_t) + reals * sizeof(Real) + ints * sizeof(Int);
  // Field by field (column blocks), so that unpacking is one copy per array.
  Bytes mine(p.size() * record);
  std::byte* at = mine.data();
  auto put = [&](const auto& a) {
    const std::size_t bytes = p.size() * sizeof(a[0]);
    if (bytes) std::memcpy(at, a.data(), bytes);
    at += bytes;
  };
  put(p.id);
  p.for_each_array(put);
  p.for_each_int_array(put);
  const std::vector<Bytes> parts = comm.gather_to_root(mine);
  if (!comm.is_root()) return whole;
  std::size_t total = 0;
  for (const Bytes& b : parts) {
    if (b.size() % record != 0) throw std::runtime_error("gather_to_root: a rank sent a partial particle record");
    total += b.size() / record;
  }
  whole.resize(total);
  std::size_t offset = 0;
  for (const Bytes& b : parts) {
    const std::size_t n = b.size() / record;
    const std::byte* from = b.data();
    auto get = [&](auto& a) {
      const std::size_t bytes = n * sizeof(a[0]);
      if (bytes) std::memcpy(a.data() + offset, from, bytes);
      from += bytes;
    };
    get(whole.id);
    whole.for_each_array(get);
    whole.for_each_int_array(get);
    offset += n;
  }
  return whole;
}

// Keeps particles [begin, end) of p, in order.
template <class Real>
void keep_range(ParticleSet<Real>& p, std::size_t begin, std::size_t end) {
  if (begin > end || end > p.size()) throw std::invalid_argument("keep_range: the range is not within the set");
  auto keep = [&](auto& a) {
    std::copy(a.begin() + static_cast<std::ptrdiff_t>(begin), a.begin() + static_cast<std::ptrdiff_t>(end), a.begin());
  };
  p.for_each_array(keep);
  p.for_each_int_array(keep);
  keep(p.id);
  p.resize(end - begin);
  auto shrink = [](auto& a) { a.shrink_to_fit(); };
  p.for_each_array(shrink);
  p.for_each_int_array(shrink);
  shrink(p.id);
}

// Collective: on every rank other than 0, p (which must hold no particles)
// becomes a set without particles with rank 0's fields in rank 0's order; a
// field p declared already must be one of them, at the same place (fields are
// found by index once declared). Rank 0's p is unchanged.
template <class Real>
void share_layout_from_root(const Communicator& comm, ParticleSet<Real>& p) {
  if (!comm.distributed()) return;
  // One line per field: "r NAME COMPONENTS INTERNAL" or "i NAME INTERNAL".
  std::string layout;
  if (comm.is_root()) {
    constexpr std::size_t kBuiltIn = 7;  // position ... pressure (ParticleSet::fields())
    const auto fields = p.fields();
    for (std::size_t k = kBuiltIn; k < fields.size(); ++k)
      layout += "r " + std::string(fields[k].name) + ' ' + std::to_string(fields[k].components) + ' ' +
                (fields[k].internal ? '1' : '0') + '\n';
    for (const auto& f : p.int_fields()) layout += "i " + std::string(f.name) + ' ' + (f.internal ? '1' : '0') + '\n';
    layout += "end\n";  // never empty: first_text passes the first non-empty text
  }
  layout = comm.first_text(layout);
  if (comm.is_root()) return;
  if (!p.empty()) throw std::logic_error("share_layout_from_root: a rank other than 0 already holds particles");
  ParticleSet<Real> s;
  std::size_t at = 0;
  while (at < layout.size()) {
    const std::size_t end = layout.find('\n', at);
    const std::string line = layout.substr(at, end - at);
    at = end + 1;
    if (line == "end") break;
    const std::size_t a = line.find(' ', 2), b = line.rfind(' ');
    const std::string name = line.substr(2, a - 2);
    const FieldUse use = line[b + 1] == '1' ? FieldUse::Internal : FieldUse::Output;
    if (line[0] == 'r') s.add_field(name, static_cast<int>(std::stoi(line.substr(a + 1, b - a - 1))), use);
    else s.add_int_field(name, use);
  }
  const auto mine = p.fields(), theirs = s.fields();
  const auto mine_int = p.int_fields(), theirs_int = s.int_fields();
  bool prefix = mine.size() <= theirs.size() && mine_int.size() <= theirs_int.size();
  for (std::size_t k = 0; prefix && k < mine.size(); ++k) prefix = mine[k].name == theirs[k].name;
  for (std::size_t k = 0; prefix && k < mine_int.size(); ++k) prefix = mine_int[k].name == theirs_int[k].name;
  if (!prefix) throw std::logic_error("share_layout_from_root: this rank declared fields rank 0 does not have in that order");
  p = std::move(s);
}

// Collective: rank 0's particles [starts[r], starts[r + 1]) go to rank r
// (starts: size() + 1 non-decreasing entries ending at rank 0's count, read on
// rank 0 only); rank 0 keeps its own slice. p must have the same fields on
// every rank (share_layout_from_root) and no particles on the others.
template <class Real>
void scatter_from_root(const Communicator& comm, ParticleSet<Real>& p, std::span<const std::size_t> starts) {
  using Int = typename ParticleSet<Real>::int_type;
  if (!comm.distributed()) return;
  std::size_t reals = 0, ints = 0;
  p.for_each_array([&](const AlignedVector<Real>&) { ++reals; });
  p.for_each_int_array([&](const AlignedVector<Int>&) { ++ints; });
  const std::size_t record = sizeof(std::uint64_t) + reals * sizeof(Real) + ints * sizeof(Int);
  const auto ranks = static_cast<std::size_t>(comm.size());
  std::vector<Bytes> send(ranks);
  if (comm.is_root()) {
    if (starts.size() != ranks + 1 || starts[0] != 0 || starts[ranks] != p.size() ||
        !std::is_sorted(starts.begin(), starts.end()))
      throw std::invalid_argument("scatter_from_root: the slices do not cover the set in order");
    for (std::size_t r = 1; r < ranks; ++r) {
      const std::size_t b = starts[r], n = starts[r + 1] - b;
      send[r].resize(n * record);
      std::byte* at = send[r].data();
      auto put = [&](const auto& a) {
        const std::size_t bytes = n * sizeof(a[0]);
        if (bytes) std::memcpy(at, a.data() + b, bytes);
        at += bytes;
      };
      put(p.id);
      p.for_each_array(put);
      p.for_each_int_array(put);
    }
  } else if (!p.empty()) {
    throw std::logic_error("scatter_from_root: a rank other than 0 already holds particles");
  }
  std::vector<Bytes> got = comm.all_to_all(send);
  send.clear();
  if (comm.is_root()) {
    keep_range(p, 0, starts[1]);
    return;
  }
  const Bytes& b = got[0];
  if (b.size() % record != 0) throw std::runtime_error("scatter_from_root: rank 0 sent a partial particle record");
  const std::size_t n = b.size() / record;
  p.resize(n);
  const std::byte* from = b.data();
  auto get = [&](auto& a) {
    const std::size_t bytes = n * sizeof(a[0]);
    if (bytes) std::memcpy(a.data(), from, bytes);
    from += bytes;
  };
  get(p.id);
  p.for_each_array(get);
  p.for_each_int_array(get);
}

}  // namespace swirl::dist
