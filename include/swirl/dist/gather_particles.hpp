// The whole particle set of a distributed run, and a rank's share of it.
//
// gather_to_root(): the ranks' particles concatenated in rank order on rank 0
// (every field, bit for bit; the other ranks get an empty set with the same
// fields). Under the distributed order's invariant (dist/key_order.hpp) that
// is the one-rank memory order, so a frame or a checkpoint written from it is
// the one-rank file byte for byte. It holds every particle on rank 0 for the
// time of one write: the simple first step before parallel HDF5 (issue 19 item 6).
//
// keep_range(): drops every particle outside [begin, end) and gives the rest
// of the memory back (a rank taking its slice of a set every rank built or
// read whole).
//
// Collective where it says so. Units: whatever the fields hold.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
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

}  // namespace swirl::dist
