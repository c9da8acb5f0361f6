// ParticleSet<Real>: the particles of one simulation as a structure of arrays.
//
// Layout (the thesis's Figure 4.1, one array per component instead of padded
// xyz quadruples, so loops vectorise over particles): every field is an
// AlignedVector whose storage starts on a 64-byte boundary.
//
// Fields: the built-in ones below, and extra fields that solvers and the
// particle order declare by name. An extra field is real (add_field: 1 or 3
// components of Real) or integer (add_int_field: 1 component of std::int32_t,
// enough for a particle kind, a flag or a small index; a per-particle count or
// index beyond 2^31 would need a wider type and a new checkpoint version). An
// extra field is either written to frames (FieldUse::Output, the default:
// ParaView shows it) or internal (FieldUse::Internal: state that travels with
// the particles and with checkpoints but is no physical output, such as the
// order's reference positions). for_each_array() visits every real array,
// built-in and extra, and for_each_int_array() every integer one: resize,
// reorders and checkpoints go through them, so a new field needs no other code.
//
// Invariants:
//  - every field, built-in or extra, real or integer, has exactly size()
//    elements per component; change the count only through resize() and the
//    order only through a reorder (reorder() here, or spatial::ParticleReorder
//    in parallel);
//  - field names are unique across built-in, real and integer fields (they are
//    the array names of one frame and of one checkpoint);
//  - id[i] is the particle's stable identity: it is set once at creation and
//    travels with the particle through every reorder().
//
// Units follow the solver: SI (m, m/s, m/s², kg, kg/m³, Pa) for SPH; G = 1
// N-body units for gravity. Integer fields carry no unit (a kind, a flag).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "swirl/core/aligned.hpp"
#include "swirl/core/vec3.hpp"

namespace swirl {

// Three component arrays of one vector field.
template <class Real>
struct Vec3Array {
  AlignedVector<Real> x, y, z;

  AlignedVector<Real>& operator[](int axis) { return axis == 0 ? x : (axis == 1 ? y : z); }
  const AlignedVector<Real>& operator[](int axis) const { return axis == 0 ? x : (axis == 1 ? y : z); }
  Vec3<Real> get(std::size_t i) const { return {x[i], y[i], z[i]}; }
  void set(std::size_t i, const Vec3<Real>& v) { x[i] = v.x; y[i] = v.y; z[i] = v.z; }
};

// A named view of one field: 1 component (scalar) or 3 (vector; real fields
// only). The name is the array name written to output files and what ParaView
// shows. T is Real (or const Real) for real fields, std::int32_t for integer ones.
template <class T>
struct FieldView {
  std::string_view name;
  int components = 1;
  std::array<T*, 3> data{};  // data[c] for c < components
  bool internal = false;     // not written to frames (FieldUse::Internal)
};

// Whether an extra field is physical output or internal state (see ParticleSet).
enum class FieldUse { Output, Internal };

template <class Real>
class ParticleSet {
 public:
  using value_type = Real;
  using int_type = std::int32_t;  // the element type of every integer field

  ParticleSet() = default;
  explicit ParticleSet(std::size_t n) { resize(n); }

  std::size_t size() const { return mass.size(); }
  bool empty() const { return size() == 0; }

  static constexpr std::size_t npos = static_cast<std::size_t>(-1);

  // Changes the particle count of every field; new entries are zero.
  void resize(std::size_t n) {
    for_each_array([n](AlignedVector<Real>& a) { a.resize(n); });
    for_each_int_array([n](AlignedVector<int_type>& a) { a.resize(n); });
    id.resize(n);
  }

  // Removes the particles i for which remove(i) is true, the others keeping
  // their order (every field and the ids); returns how many were removed.
  template <class Remove>
  std::size_t remove_if(Remove&& remove) {
    std::vector<std::size_t> kept;
    kept.reserve(size());
    for (std::size_t i = 0; i < size(); ++i)
      if (!remove(i)) kept.push_back(i);
    const std::size_t removed = size() - kept.size();
    if (removed == 0) return 0;
    // kept[k] ≥ k: moving forward in place never overwrites an entry still to move.
    const auto compact = [&](auto& a) {
      for (std::size_t k = 0; k < kept.size(); ++k) a[k] = a[kept[k]];
      a.resize(kept.size());
    };
    for_each_array(compact);
    for_each_int_array(compact);
    compact(id);
    return removed;
  }

  // A new set with this one's fields (names, shapes, uses) holding copies of
  // the particles picked[0], picked[1], ... in that order (each index < size()).
  ParticleSet subset(std::span<const std::size_t> picked) const {
    ParticleSet out;
    for (const auto& e : extra_) out.extra_.push_back({e.name, e.components, e.use, {}});
    for (const auto& e : int_extra_) out.int_extra_.push_back({e.name, e.use, {}});
    out.resize(picked.size());
    // Both sets' arrays are visited in the same order.
    std::vector<const AlignedVector<Real>*> from;
    for_each_array([&](const AlignedVector<Real>& a) { from.push_back(&a); });
    std::vector<const AlignedVector<int_type>*> int_from;
    for_each_int_array([&](const AlignedVector<int_type>& a) { int_from.push_back(&a); });
    const auto gather = [&](auto& to, const auto& src) {
      for (std::size_t k = 0; k < picked.size(); ++k) to[k] = src.at(picked[k]);
    };
    std::size_t next = 0;
    out.for_each_array([&](AlignedVector<Real>& a) { gather(a, *from[next++]); });
    next = 0;
    out.for_each_int_array([&](AlignedVector<int_type>& a) { gather(a, *int_from[next++]); });
    gather(out.id, id);
    return out;
  }

  // Calls f(AlignedVector<Real>&) for every real array, built-in and extra, in
  // fields() order (component by component). The ids are not included.
  // Allocates nothing (unlike fields()): cheap enough for a per-block pass.
  template <class F>
  void for_each_array(F&& f) {
    for_each_array_impl(*this, f);
  }
  template <class F>
  void for_each_array(F&& f) const {
    for_each_array_impl(*this, f);
  }

  // Calls f(AlignedVector<int_type>&) for every integer field, in int_fields() order.
  template <class F>
  void for_each_int_array(F&& f) {
    for (auto& e : int_extra_) f(e.data);
  }
  template <class F>
  void for_each_int_array(F&& f) const {
    for (const auto& e : int_extra_) f(e.data);
  }

  // Adds an extra field (zero-filled) and returns its index; if a field of that
  // name and shape exists already, returns its index (and keeps its use).
  std::size_t add_field(std::string name, int components, FieldUse use = FieldUse::Output) {
    if (components != 1 && components != 3) throw std::invalid_argument("a field has 1 or 3 components");
    for (std::size_t k = 0; k < extra_.size(); ++k) {
      if (extra_[k].name == name) {
        if (extra_[k].components != components) throw std::invalid_argument("field '" + name + "' exists with another shape");
        return k;
      }
    }
    if (is_builtin_name(name)) throw std::invalid_argument("field '" + name + "' is a built-in field");
    if (find_int_field(name) != npos) throw std::invalid_argument("field '" + name + "' exists as an integer field");
    ExtraField f{std::move(name), components, use, {}};
    for (int c = 0; c < components; ++c) f.data[static_cast<std::size_t>(c)].assign(size(), Real(0));
    extra_.push_back(std::move(f));
    return extra_.size() - 1;
  }
  // The index of the extra field `name`, or npos.
  std::size_t find_field(std::string_view name) const {
    for (std::size_t k = 0; k < extra_.size(); ++k)
      if (extra_[k].name == name) return k;
    return npos;
  }
  // Component c of extra field k (as returned by add_field).
  AlignedVector<Real>& extra(std::size_t k, int c = 0) { return extra_.at(k).data.at(c); }
  const AlignedVector<Real>& extra(std::size_t k, int c = 0) const { return extra_.at(k).data.at(c); }
  std::size_t extra_count() const { return extra_.size(); }

  // Adds an integer field (one std::int32_t per particle, zero-filled) and
  // returns its index; if an integer field of that name exists already,
  // returns its index (and keeps its use). A name taken by a built-in or a
  // real field is refused.
  std::size_t add_int_field(std::string name, FieldUse use = FieldUse::Output) {
    if (const std::size_t k = find_int_field(name); k != npos) return k;
    if (is_builtin_name(name)) throw std::invalid_argument("field '" + name + "' is a built-in field");
    if (find_field(name) != npos) throw std::invalid_argument("field '" + name + "' exists as a real field");
    IntField f{std::move(name), use, {}};
    f.data.assign(size(), int_type(0));
    int_extra_.push_back(std::move(f));
    return int_extra_.size() - 1;
  }
  // The index of the integer field `name`, or npos.
  std::size_t find_int_field(std::string_view name) const {
    for (std::size_t k = 0; k < int_extra_.size(); ++k)
      if (int_extra_[k].name == name) return k;
    return npos;
  }
  // Integer field k (as returned by add_int_field).
  AlignedVector<int_type>& int_field(std::size_t k) { return int_extra_.at(k).data; }
  const AlignedVector<int_type>& int_field(std::size_t k) const { return int_extra_.at(k).data; }
  std::size_t int_field_count() const { return int_extra_.size(); }

  // Permutes every field so that the particle at old index perm[i] moves to
  // index i (a gather). perm must be a permutation of 0..size()-1.
  void reorder(std::span<const std::size_t> perm) {
    check_permutation(perm);
    AlignedVector<Real> scratch(size());
    for_each_array([&](AlignedVector<Real>& a) {
      for (std::size_t i = 0; i < perm.size(); ++i) scratch[i] = a[perm[i]];
      a.swap(scratch);
    });
    AlignedVector<int_type> int_scratch(int_extra_.empty() ? 0 : size());
    for_each_int_array([&](AlignedVector<int_type>& a) {
      for (std::size_t i = 0; i < perm.size(); ++i) int_scratch[i] = a[perm[i]];
      a.swap(int_scratch);
    });
    AlignedVector<std::uint64_t> ids(size());
    for (std::size_t i = 0; i < perm.size(); ++i) ids[i] = id[perm[i]];
    id.swap(ids);
  }

  // Every real-valued field (position first, then the other built-ins, then the
  // extra fields in creation order): what writers and checkpoints iterate over.
  // The id array is not real-valued and is reached directly.
  std::vector<FieldView<const Real>> fields() const { return fields_impl<const Real>(*this); }
  std::vector<FieldView<Real>> fields() { return fields_impl<Real>(*this); }

  // Every integer field in creation order (1 component each): what writers
  // and checkpoints iterate over after the real fields.
  std::vector<FieldView<const int_type>> int_fields() const { return int_fields_impl<const int_type>(*this); }
  std::vector<FieldView<int_type>> int_fields() { return int_fields_impl<int_type>(*this); }

  // Built-in fields (see the units note above).
  Vec3Array<Real> position;           // x
  Vec3Array<Real> velocity;           // v
  Vec3Array<Real> acceleration;       // a at the current positions
  Vec3Array<Real> acceleration_prev;  // a of the previous step (velocity Verlet)
  AlignedVector<Real> mass;           // m, constant in time
  AlignedVector<Real> density;        // ρ (SPH)
  AlignedVector<Real> pressure;       // p (SPH)
  AlignedVector<std::uint64_t> id;    // stable identity, survives reorder()

 private:
  struct ExtraField {
    std::string name;
    int components = 1;
    FieldUse use = FieldUse::Output;
    std::array<AlignedVector<Real>, 3> data;
  };
  struct IntField {
    std::string name;
    FieldUse use = FieldUse::Output;
    AlignedVector<int_type> data;
  };

  static bool is_builtin_name(std::string_view n) {
    for (auto b : {"position", "velocity", "acceleration", "acceleration_prev", "mass", "density", "pressure", "id"})
      if (n == b) return true;
    return false;
  }

  void check_permutation(std::span<const std::size_t> perm) const {
    if (perm.size() != size()) throw std::invalid_argument("reorder: permutation has the wrong length");
    std::vector<bool> seen(perm.size(), false);
    for (std::size_t p : perm) {
      if (p >= perm.size() || seen[p]) throw std::invalid_argument("reorder: not a permutation");
      seen[p] = true;
    }
  }

  template <class Self, class F>
  static void for_each_array_impl(Self& self, F& f) {
    for (auto* v : {&self.position, &self.velocity, &self.acceleration, &self.acceleration_prev})
      for (int a = 0; a < 3; ++a) f((*v)[a]);
    f(self.mass);
    f(self.density);
    f(self.pressure);
    for (auto& e : self.extra_)
      for (int c = 0; c < e.components; ++c) f(e.data[static_cast<std::size_t>(c)]);
  }

  template <class T, class Self>
  static std::vector<FieldView<T>> fields_impl(Self& self) {
    std::vector<FieldView<T>> out;
    auto vec = [&](std::string_view n, auto& v) {
      out.push_back({n, 3, {v.x.data(), v.y.data(), v.z.data()}});
    };
    auto scalar = [&](std::string_view n, auto& a) { out.push_back({n, 1, {a.data(), nullptr, nullptr}}); };
    vec("position", self.position);
    vec("velocity", self.velocity);
    vec("acceleration", self.acceleration);
    vec("acceleration_prev", self.acceleration_prev);
    scalar("mass", self.mass);
    scalar("density", self.density);
    scalar("pressure", self.pressure);
    for (auto& f : self.extra_) {
      FieldView<T> v{f.name, f.components, {}, f.use == FieldUse::Internal};
      for (int c = 0; c < f.components; ++c) v.data[c] = f.data[c].data();
      out.push_back(v);
    }
    return out;
  }

  template <class T, class Self>
  static std::vector<FieldView<T>> int_fields_impl(Self& self) {
    std::vector<FieldView<T>> out;
    for (auto& f : self.int_extra_) out.push_back({f.name, 1, {f.data.data(), nullptr, nullptr}, f.use == FieldUse::Internal});
    return out;
  }

  std::vector<ExtraField> extra_;
  std::vector<IntField> int_extra_;
};

// Compiled once, in src/core/particle_set.cpp: users link the float and double copies
// instead of compiling them again.
extern template struct Vec3Array<float>;
extern template struct Vec3Array<double>;
extern template class ParticleSet<float>;
extern template class ParticleSet<double>;

}  // namespace swirl
