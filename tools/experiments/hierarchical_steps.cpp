// An experiment, not part of swirl's build: does the hierarchical splitting of
// individual time steps (HOLD: Pelupessy, Jänes & Portegies Zwart 2012, the
// scheme of Gadget-4's hierarchical gravity) save force evaluations against one
// global step at equal energy error, where swirl's block leapfrog did not?
// And the fourth-order Hermite block scheme of collisional codes (`hermite`).
// (docs/performance/block-steps.md, "The hierarchical splitting".)
//
// Forces by the softened direct sum (G = 1, Plummer ε, float64), so that the
// answer is about the integrators, not a tree's force errors.
//
//   global  kick–drift–kick leapfrog, one step for all: Δt = min(Δt_max, η·min_i c_i)
//   hold    drift–kick–drift hierarchical splitting on power-of-two levels:
//           particle i on level k_i (step Δt_max / 2^k_i, the smallest k with
//           the step ≤ η·c_i); a PAIR (i, j) is kicked by its mutual force at
//           the coarser level min(k_i, k_j), both members at once, in the
//           middle of that level's steps (the two halves of a level-n step
//           hold the level-(n+1) steps: H_n = T_n + V_n + H_{n+1}), so momentum
//           is conserved exactly and the map is symplectic while the levels
//           stay fixed. Levels change where a particle's step starts.
//           With --frozen the levels of the first step are kept for the run.
//   hermite fourth-order Hermite with block steps and Aarseth's condition
//           (run_hermite below; the condition argument is not used)
//
// Conditions c_i: accel sqrt(ε/|a_i|) (swirl's block steps), tidal
// 1/sqrt(Σ_j m_j/(r_ij²+ε²)^{3/2}) (a bound on the tide's scale, whose
// pair terms give close pairs small steps), both = the smaller. On the hold
// levels a particle's a and tide are the sums of the last partial kicks of
// each level (as the forces are only ever computed per level).
//
// Printed: |ΔE/E| at the end and its largest value sampled every time unit;
// sink evaluations (particles whose force a kick computed) and pair
// interactions (the direct sum's cost); wall time (2 threads: OMP_NUM_THREADS).
//
// Build and run (initial conditions: positions, velocities, masses as float64
// rows of 7, e.g. from a swirl HDF5 frame):
//   g++ -std=c++20 -O3 -march=native -fno-math-errno -fopenmp
//       tools/experiments/hierarchical_steps.cpp -o /tmp/hierarchical_steps
//   /usr/bin/python3 -c "import h5py, numpy as np; g = h5py.File('out/ic/particles_000000.h5')['PartType1'];
//       np.hstack([g['Coordinates'][:], g['Velocities'][:], g['Masses'][:][:, None]]).astype('f8').tofile('/tmp/ic.bin')"
//   (each command on one line)
//   /tmp/hierarchical_steps /tmp/ic.bin hold tidal 0.025 0.0625 10 [--softening 0.02] [--max-level 16] [--frozen]
#include <omp.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using std::vector;

struct Bodies {
  vector<double> x, y, z, vx, vy, vz, m;
  int size() const { return int(m.size()); }
};

// Sources gathered into contiguous arrays (the inner loop vectorises).
struct Sources {
  vector<double> x, y, z, m;
  vector<char> member;  // by body index: is it one of these sources
  void reset(int n) {
    x.clear(), y.clear(), z.clear(), m.clear();
    member.assign(std::size_t(n), 0);
  }
  void add(const Bodies& b, int j) {
    x.push_back(b.x[j]), y.push_back(b.y[j]), z.push_back(b.z[j]), m.push_back(b.m[j]);
    member[std::size_t(j)] = 1;
  }
};

struct Field {
  vector<double> ax, ay, az, tide, pot;
  void resize(std::size_t n) { ax.resize(n), ay.resize(n), az.resize(n), tide.resize(n), pot.resize(n); }
};

struct Cost {
  double sink_evaluations = 0, pairs = 0;
};

class Experiment {
 public:
  Experiment(Bodies b, double eps) : b_(std::move(b)), eps_(eps) {}

  // Field of `sources` at the sinks (self terms removed), into f[0 .. sinks.size()).
  void field(const vector<int>& sinks, const Sources& s, Field& f, Cost* cost) const {
    f.resize(std::max(f.ax.size(), sinks.size()));
    const int ns = int(s.m.size());
    const double eps2 = eps_ * eps_;
    if (cost) cost->sink_evaluations += double(sinks.size()), cost->pairs += double(sinks.size()) * ns;
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < sinks.size(); ++k) {
      const int i = sinks[k];
      const double xi = b_.x[i], yi = b_.y[i], zi = b_.z[i];
      double sx = 0, sy = 0, sz = 0, st = 0, sp = 0;
#pragma omp simd reduction(+ : sx, sy, sz, st, sp)
      for (int j = 0; j < ns; ++j) {
        const double dx = s.x[j] - xi, dy = s.y[j] - yi, dz = s.z[j] - zi;
        const double ir = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz + eps2);
        const double mr3 = s.m[j] * ir * ir * ir;
        sx += mr3 * dx, sy += mr3 * dy, sz += mr3 * dz, st += mr3, sp -= s.m[j] * ir;
      }
      if (s.member[std::size_t(i)]) st -= b_.m[i] / (eps_ * eps2), sp += b_.m[i] / eps_;
      f.ax[k] = sx, f.ay[k] = sy, f.az[k] = sz, f.tide[k] = st, f.pot[k] = sp;
    }
  }

  double energy() const {
    const int n = b_.size();
    vector<int> all(std::size_t(n), 0);
    for (int i = 0; i < n; ++i) all[std::size_t(i)] = i;
    Sources s;
    s.reset(n);
    for (int j = 0; j < n; ++j) s.add(b_, j);
    Field f;
    field(all, s, f, nullptr);
    double e = 0;
    for (int i = 0; i < n; ++i)
      e += 0.5 * b_.m[i] * (b_.vx[i] * b_.vx[i] + b_.vy[i] * b_.vy[i] + b_.vz[i] * b_.vz[i] + f.pot[std::size_t(i)]);
    return e;
  }

  void drift(double h) {
    const int n = b_.size();
#pragma omp parallel for simd
    for (int i = 0; i < n; ++i) b_.x[i] += b_.vx[i] * h, b_.y[i] += b_.vy[i] * h, b_.z[i] += b_.vz[i] * h;
  }
  void kick(int i, double h, double ax, double ay, double az) {
    b_.vx[i] += h * ax, b_.vy[i] += h * ay, b_.vz[i] += h * az;
  }

  const Bodies& bodies() const { return b_; }

 private:
  Bodies b_;
  double eps_;
};

struct Options {
  std::string scheme, condition;
  double eta = 0, dt_max = 0, t_end = 0, eps = 0.02;
  int max_level = 16;
  bool frozen = false;
};

double step_condition(const Options& o, double ax, double ay, double az, double tide) {
  const double a = std::sqrt(ax * ax + ay * ay + az * az);
  const double by_accel = a > 0 ? o.eta * std::sqrt(o.eps / a) : HUGE_VAL;
  const double by_tide = tide > 0 ? o.eta / std::sqrt(tide) : HUGE_VAL;
  if (o.condition == "accel") return by_accel;
  if (o.condition == "tidal") return by_tide;
  return std::min(by_accel, by_tide);
}

// Fourth-order Hermite with block steps (Makino & Aarseth 1992), the
// integrator of collisional N-body codes: every body predicted to the next
// block time, the active ones' a and jerk from the predicted state (direct
// sum), corrected; the step from Aarseth's condition
// sqrt(η·(|a||a⁽²⁾| + |j|²)/(|j||a⁽³⁾| + |a⁽²⁾|²)), halved as needed, doubled at
// most once a step and only where the time allows. Not a leapfrog: the
// comparison the issue asks for is the leapfrog's, this shows what a
// higher-order integrator would change.
struct HermiteResult {
  double worst = 0, final_error = 0, sink_evaluations = 0;
  int finest = 0;
};

HermiteResult run_hermite(Bodies b, const Options& o) {
  const int n = b.size();
  const double eps2 = o.eps * o.eps;
  std::vector<double> px(n), py(n), pz(n), pvx(n), pvy(n), pvz(n);
  std::vector<double> ax(n), ay(n), az(n), jx(n), jy(n), jz(n), t_i(n, 0), dt_i(n);
  std::vector<double> nax(n), nay(n), naz(n), njx(n), njy(n), njz(n);
  HermiteResult r;
  auto force_jerk = [&](const std::vector<int>& sinks) {
    r.sink_evaluations += double(sinks.size());
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < sinks.size(); ++k) {
      const int i = sinks[k];
      double sx = 0, sy = 0, sz = 0, qx = 0, qy = 0, qz = 0;
#pragma omp simd reduction(+ : sx, sy, sz, qx, qy, qz)
      for (int j = 0; j < n; ++j) {
        const double dx = px[j] - px[i], dy = py[j] - py[i], dz = pz[j] - pz[i];
        const double dvx = pvx[j] - pvx[i], dvy = pvy[j] - pvy[i], dvz = pvz[j] - pvz[i];
        const double r2 = dx * dx + dy * dy + dz * dz + eps2;
        const double ir = 1.0 / std::sqrt(r2), ir2 = ir * ir;
        const double mr3 = (j == i ? 0.0 : b.m[j]) * ir * ir2;
        const double rv = 3.0 * (dx * dvx + dy * dvy + dz * dvz) * ir2;
        sx += mr3 * dx, sy += mr3 * dy, sz += mr3 * dz;
        qx += mr3 * (dvx - rv * dx), qy += mr3 * (dvy - rv * dy), qz += mr3 * (dvz - rv * dz);
      }
      nax[i] = sx, nay[i] = sy, naz[i] = sz, njx[i] = qx, njy[i] = qy, njz[i] = qz;
    }
  };
  auto energy = [&] {  // all bodies synchronised
    Experiment ex(b, o.eps);
    return ex.energy();
  };
  const double e0 = energy();
  for (int i = 0; i < n; ++i) px[i] = b.x[i], py[i] = b.y[i], pz[i] = b.z[i], pvx[i] = b.vx[i], pvy[i] = b.vy[i], pvz[i] = b.vz[i];
  std::vector<int> active(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) active[std::size_t(i)] = i;
  force_jerk(active);
  const double smallest = std::ldexp(o.dt_max, -o.max_level);
  auto block = [&](double want, double t, double limit) {  // largest power-of-two step ≤ want, ≤ limit, dividing t
    double dt = limit;
    while (dt > want && dt > smallest) dt *= 0.5;
    while (dt > smallest && std::fmod(t, dt) != 0) dt *= 0.5;
    return dt;
  };
  for (int i = 0; i < n; ++i) {
    ax[i] = nax[i], ay[i] = nay[i], az[i] = naz[i], jx[i] = njx[i], jy[i] = njy[i], jz[i] = njz[i];
    const double a = std::sqrt(ax[i] * ax[i] + ay[i] * ay[i] + az[i] * az[i]);
    const double j = std::sqrt(jx[i] * jx[i] + jy[i] * jy[i] + jz[i] * jz[i]);
    dt_i[i] = block(j > 0 ? 0.01 * a / j : o.dt_max, 0, o.dt_max);  // a cautious first step
  }
  double t = 0, next_sample = 1;
  while (t < o.t_end - 1e-12) {
    double t_next = HUGE_VAL;
    for (int i = 0; i < n; ++i) t_next = std::min(t_next, t_i[i] + dt_i[i]);
    active.clear();
    for (int i = 0; i < n; ++i) {
      const double d = t_next - t_i[i], d2 = d * d / 2, d3 = d * d * d / 6;
      px[i] = b.x[i] + b.vx[i] * d + ax[i] * d2 + jx[i] * d3;
      py[i] = b.y[i] + b.vy[i] * d + ay[i] * d2 + jy[i] * d3;
      pz[i] = b.z[i] + b.vz[i] * d + az[i] * d2 + jz[i] * d3;
      pvx[i] = b.vx[i] + ax[i] * d + jx[i] * d2, pvy[i] = b.vy[i] + ay[i] * d + jy[i] * d2,
      pvz[i] = b.vz[i] + az[i] * d + jz[i] * d2;
      if (t_i[i] + dt_i[i] == t_next) active.push_back(i);
    }
    force_jerk(active);
    for (const int i : active) {
      const double h = dt_i[i];
      const double* a0[3] = {&ax[i], &ay[i], &az[i]};
      const double* j0[3] = {&jx[i], &jy[i], &jz[i]};
      const double a1[3] = {nax[i], nay[i], naz[i]}, j1[3] = {njx[i], njy[i], njz[i]};
      double* xs[3] = {&b.x[i], &b.y[i], &b.z[i]};
      double* vs[3] = {&b.vx[i], &b.vy[i], &b.vz[i]};
      const double pp[3] = {px[i], py[i], pz[i]}, pv[3] = {pvx[i], pvy[i], pvz[i]};
      double s2 = 0, s3 = 0, sa = 0, sj = 0;
      for (int c = 0; c < 3; ++c) {
        const double a2 = (-6 * (*a0[c] - a1[c]) - h * (4 * *j0[c] + 2 * j1[c])) / (h * h);
        const double a3 = (12 * (*a0[c] - a1[c]) + 6 * h * (*j0[c] + j1[c])) / (h * h * h);
        *xs[c] = pp[c] + a2 * h * h * h * h / 24 + a3 * h * h * h * h * h / 120;
        *vs[c] = pv[c] + a2 * h * h * h / 6 + a3 * h * h * h * h / 24;
        const double a2_end = a2 + h * a3;
        s2 += a2_end * a2_end, s3 += a3 * a3, sa += a1[c] * a1[c], sj += j1[c] * j1[c];
      }
      ax[i] = a1[0], ay[i] = a1[1], az[i] = a1[2], jx[i] = j1[0], jy[i] = j1[1], jz[i] = j1[2];
      t_i[i] = t_next;
      const double num = std::sqrt(sa) * std::sqrt(s2) + sj, den = std::sqrt(sj) * std::sqrt(s3) + s2;
      const double want = den > 0 ? std::sqrt(o.eta * num / den) : o.dt_max;
      const double limit = std::min(o.dt_max, 2 * h);  // at most one doubling
      dt_i[i] = block(want, t_next, limit);
      r.finest = std::max(r.finest, int(std::lround(std::log2(o.dt_max / dt_i[i]))));
    }
    t = t_next;
    if (std::fmod(t, o.dt_max) == 0 && t >= next_sample - 1e-12) {  // every body synchronised
      r.worst = std::max(r.worst, std::fabs(energy() / e0 - 1));
      next_sample += 1;
    }
  }
  r.final_error = std::fabs(energy() / e0 - 1);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  vector<std::string> pos;
  for (int a = 1; a < argc; ++a) {
    const std::string s = argv[a];
    if (s == "--frozen") o.frozen = true;
    else if (s == "--softening" && a + 1 < argc) o.eps = std::atof(argv[++a]);
    else if (s == "--max-level" && a + 1 < argc) o.max_level = std::atoi(argv[++a]);
    else pos.push_back(s);
  }
  if (pos.size() != 6 || (pos[1] != "global" && pos[1] != "hold" && pos[1] != "hermite") ||
      (pos[2] != "accel" && pos[2] != "tidal" && pos[2] != "both")) {
    std::fprintf(stderr,
                 "usage: %s IC.bin global|hold|hermite accel|tidal|both ETA DT_MAX T_END [--softening E] [--max-level K] "
                 "[--frozen]\n",
                 argv[0]);
    return 2;
  }
  o.scheme = pos[1], o.condition = pos[2];
  o.eta = std::atof(pos[3].c_str()), o.dt_max = std::atof(pos[4].c_str()), o.t_end = std::atof(pos[5].c_str());
  if (!(o.eta > 0) || !(o.dt_max > 0) || !(o.t_end > 0) || !(o.eps > 0) || o.max_level < 0 || o.max_level > 40) {
    std::fprintf(stderr, "ETA, DT_MAX, T_END and the softening must be > 0, the max level in [0, 40]\n");
    return 2;
  }
  Bodies b;
  {
    std::FILE* f = std::fopen(pos[0].c_str(), "rb");
    if (!f) return std::fprintf(stderr, "%s: cannot open\n", pos[0].c_str()), 2;
    vector<double> row(7);
    while (std::fread(row.data(), sizeof(double), 7, f) == 7) {
      b.x.push_back(row[0]), b.y.push_back(row[1]), b.z.push_back(row[2]);
      b.vx.push_back(row[3]), b.vy.push_back(row[4]), b.vz.push_back(row[5]), b.m.push_back(row[6]);
    }
    std::fclose(f);
  }
  const int n = b.size();
  if (n < 2) return std::fprintf(stderr, "%s: fewer than two bodies\n", pos[0].c_str()), 2;
  if (o.scheme == "hermite") {
    const double wall = omp_get_wtime();
    const HermiteResult h = run_hermite(b, o);
    std::printf("hermite eta %g dt_max %g t %g: |dE/E| end %.3e largest %.3e  sink evaluations %.4e pairs %.4e "
                "finest level %d wall %.1f s\n",
                o.eta, o.dt_max, o.t_end, h.final_error, h.worst, h.sink_evaluations, h.sink_evaluations * n,
                h.finest, omp_get_wtime() - wall);
    return 0;
  }
  Experiment ex(std::move(b), o.eps);
  const double e0 = ex.energy();
  double worst = 0, t = 0, next_sample = 1;
  long steps = 0;
  int finest_seen = 0;
  Cost cost;
  const double wall0 = omp_get_wtime();
  vector<int> all(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) all[std::size_t(i)] = i;
  Sources everyone;
  Field f;
  auto sample = [&] {
    if (t >= next_sample - 1e-12) worst = std::max(worst, std::fabs(ex.energy() / e0 - 1)), next_sample += 1;
  };

  if (o.scheme == "global") {
    auto evaluate = [&] {
      everyone.reset(n);
      for (int j = 0; j < n; ++j) everyone.add(ex.bodies(), j);
      ex.field(all, everyone, f, &cost);
    };
    auto half_kick = [&](double h) {
      for (int i = 0; i < n; ++i) ex.kick(i, 0.5 * h, f.ax[std::size_t(i)], f.ay[std::size_t(i)], f.az[std::size_t(i)]);
    };
    evaluate();
    while (t < o.t_end - 1e-12) {
      double dt = o.dt_max;
      for (std::size_t i = 0; i < std::size_t(n); ++i)
        dt = std::min(dt, step_condition(o, f.ax[i], f.ay[i], f.az[i], f.tide[i]));
      dt = std::min(dt, o.t_end - t);
      half_kick(dt);
      ex.drift(dt);
      evaluate();
      half_kick(dt);
      t += dt, ++steps;
      sample();
    }
  } else {
    // Per body and level: the last partial kick's a and tide (sources of that level only).
    const std::size_t L = std::size_t(o.max_level) + 1;
    vector<double> pax(n * L, 0), pay(n * L, 0), paz(n * L, 0), ptide(n * L, 0);
    vector<int> level(std::size_t(n), 0);
    everyone.reset(n);
    for (int j = 0; j < n; ++j) everyone.add(ex.bodies(), j);
    ex.field(all, everyone, f, &cost);
    for (std::size_t i = 0; i < std::size_t(n); ++i)
      pax[i * L] = f.ax[i], pay[i * L] = f.ay[i], paz[i * L] = f.az[i], ptide[i * L] = f.tide[i];
    auto wanted = [&](std::size_t i) {
      double ax = 0, ay = 0, az = 0, tide = 0;
      for (std::size_t l = 0; l < L; ++l) ax += pax[i * L + l], ay += pay[i * L + l], az += paz[i * L + l], tide += ptide[i * L + l];
      const double limit = step_condition(o, ax, ay, az, tide);
      int k = 0;
      while (k < o.max_level && std::ldexp(o.dt_max, -k) > limit) ++k;
      return k;
    };
    // Ticks of Δt_max / 2^(max_level+1): level n kicks at odd multiples of 2^(max_level−n).
    const std::uint64_t end = std::uint64_t(1) << (o.max_level + 1);
    const double tick = o.dt_max / double(end);
    vector<int> own_level, finer;  // the two sink sets of a level's kick
    Sources from_level_up, from_level;
    while (t < o.t_end - 1e-12) {
      const bool rebin = !(o.frozen && steps > 0);
      int finest = 0;
      for (std::size_t i = 0; i < std::size_t(n); ++i) {
        if (rebin) level[i] = wanted(i);
        finest = std::max(finest, level[i]);
      }
      std::uint64_t now = 0;
      while (true) {
        const std::uint64_t stride = std::uint64_t(1) << (o.max_level - finest);
        const std::uint64_t next = (now / stride + 1) * stride;
        ex.drift(double(next - now) * tick);
        now = next;
        if (now == end) break;
        const int kick_level = o.max_level - std::countr_zero(now);
        // Pairs whose coarser member is on kick_level: bodies on it feel every
        // body on it or finer; bodies finer feel the bodies on it.
        own_level.clear(), finer.clear();
        from_level_up.reset(n), from_level.reset(n);
        for (int i = 0; i < n; ++i) {
          const int k = level[std::size_t(i)];
          if (k >= kick_level) from_level_up.add(ex.bodies(), i);
          if (k == kick_level) from_level.add(ex.bodies(), i), own_level.push_back(i);
          if (k > kick_level) finer.push_back(i);
        }
        const double h = std::ldexp(o.dt_max, -kick_level);
        for (int pass = 0; pass < 2; ++pass) {
          const vector<int>& sinks = pass == 0 ? own_level : finer;
          if (sinks.empty()) continue;
          ex.field(sinks, pass == 0 ? from_level_up : from_level, f, &cost);
          for (std::size_t k = 0; k < sinks.size(); ++k) {
            const std::size_t i = std::size_t(sinks[k]);
            ex.kick(int(i), h, f.ax[k], f.ay[k], f.az[k]);
            const std::size_t at = i * L + std::size_t(kick_level);
            pax[at] = f.ax[k], pay[at] = f.ay[k], paz[at] = f.az[k], ptide[at] = f.tide[k];
            if (pass == 0)  // these sources were every level from kick_level up
              for (std::size_t l = std::size_t(kick_level) + 1; l < L; ++l)
                pax[i * L + l] = pay[i * L + l] = paz[i * L + l] = ptide[i * L + l] = 0;
          }
        }
        // Steps of the levels finer than kick_level start now.
        finest = 0;
        for (std::size_t i = 0; i < std::size_t(n); ++i) {
          if (rebin && level[i] > kick_level) level[i] = std::max(wanted(i), kick_level + 1);
          finest = std::max(finest, level[i]);
        }
        finest_seen = std::max(finest_seen, finest);
      }
      t += o.dt_max, ++steps;
      sample();
    }
  }
  std::printf("%s %s%s eta %g dt_max %g t %g: |dE/E| end %.3e largest %.3e  sink evaluations %.4e pairs %.4e "
              "steps %ld finest level %d wall %.1f s\n",
              o.scheme.c_str(), o.condition.c_str(), o.frozen ? " frozen" : "", o.eta, o.dt_max, t,
              std::fabs(ex.energy() / e0 - 1), worst, cost.sink_evaluations, cost.pairs, steps, finest_seen,
              omp_get_wtime() - wall0);
}
