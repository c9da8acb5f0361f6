// Communicator: the ranks of one run (MPI processes), and the few collective
// operations the distributed pieces need, all of them exact (integer sums,
// min, max, byte exchanges) so that nothing they return depends on the number
// of ranks or on the order in which messages arrive.
//
// One binary: built with MPI (CMake option SWIRL_MPI) and started by mpirun,
// world() is MPI_COMM_WORLD; otherwise (no MPI in the build, or a plain start
// without a launcher) it is a single rank and every operation is the identity.
// MPI's header stays in src/dist/communicator.cpp: nothing else sees it.
//
// MpiSession owns MPI's lifetime (one per process, in main): it initialises MPI
// only when a launcher started the process (mpirun sets OMPI_COMM_WORLD_SIZE,
// PMI_SIZE or PMIX_RANK), with MPI_THREAD_FUNNELED (OpenMP threads never call
// MPI), and finalises it at exit. abort() ends every rank at once with the
// given exit status (MPI_Abort): an error on one rank must never leave the
// others waiting in a collective.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace swirl::dist {

using Bytes = std::vector<std::byte>;

// Trivially copyable values as a message, and back: what a rank sends is an
// array of records (ids, reals, small structs) copied byte for byte.
template <class T>
Bytes to_bytes(std::span<const T> values) {
  static_assert(std::is_trivially_copyable_v<T>);
  Bytes b(values.size_bytes());
  if (!values.empty()) std::memcpy(b.data(), values.data(), b.size());
  return b;
}
// Appends the records of message `b` to `out`. Throws std::runtime_error
// naming `what` when b is not a whole number of records.
template <class T>
void append_values(const Bytes& b, std::vector<T>& out, const char* what) {
  static_assert(std::is_trivially_copyable_v<T>);
  if (b.size() % sizeof(T) != 0) throw std::runtime_error(std::string(what) + ": a rank sent a partial record");
  const std::size_t at = out.size();
  out.resize(at + b.size() / sizeof(T));
  if (!b.empty()) std::memcpy(out.data() + at, b.data(), b.size());
}

// What one rank's collectives moved (counted on several ranks only; a single
// rank moves nothing). A logical count, independent of how MPI routes the
// data: each payload this rank hands to another rank is one message of its
// bytes — all_to_all's non-empty buffers, an all-gather's contribution once
// per other rank, a reduction's values once, a gather's contribution from a
// rank other than 0 — and the bytes received likewise.
struct Traffic {
  std::uint64_t collectives = 0;  // operations called (each one or two MPI collectives)
  std::uint64_t messages = 0;     // payloads sent to other ranks
  std::uint64_t bytes_sent = 0;
  std::uint64_t bytes_received = 0;

  Traffic& operator+=(const Traffic& o) {
    collectives += o.collectives, messages += o.messages, bytes_sent += o.bytes_sent, bytes_received += o.bytes_received;
    return *this;
  }
  friend Traffic operator-(Traffic a, const Traffic& b) {
    a.collectives -= b.collectives, a.messages -= b.messages, a.bytes_sent -= b.bytes_sent;
    a.bytes_received -= b.bytes_received;
    return a;
  }
};

class Communicator {
 public:
  // The ranks of this process's run: MPI_COMM_WORLD under an MpiSession, one rank otherwise.
  static const Communicator& world();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool distributed() const { return size_ > 1; }
  bool is_root() const { return rank_ == 0; }

  // Element-wise exact reductions, the result on every rank.
  void sum(std::span<std::uint64_t> values) const;
  void min(std::span<double> values) const;
  void max(std::span<double> values) const;
  std::uint64_t sum(std::uint64_t value) const;
  // The sum of value over the ranks below this one (0 on rank 0).
  std::uint64_t exclusive_prefix_sum(std::uint64_t value) const;
  // value from every rank, in rank order, on every rank.
  std::vector<std::uint64_t> all_gather(std::uint64_t value) const;

  // Personalised exchange: send[d] goes to rank d; returns what each rank sent
  // here, indexed by source rank (send.size() must be size()).
  std::vector<Bytes> all_to_all(const std::vector<Bytes>& send) const;

  // Every rank's bytes on every rank, in rank order (each rank's may differ in length).
  std::vector<Bytes> all_gather(const Bytes& mine) const;

  // The text of the lowest rank whose text is not empty, on every rank (empty
  // when every rank's is): a failure's words, the owner's description of a
  // particle, rank 0's choice of a file (the other ranks passing "").
  std::string first_text(const std::string& mine) const;

  // Every rank's bytes on rank 0, in rank order (other ranks get an empty list).
  std::vector<Bytes> gather_to_root(const Bytes& mine) const;

  void barrier() const;

  // Ends every rank of the run with this exit status (never returns).
  [[noreturn]] void abort(int exit_status) const;

  // This rank's traffic since the start (see Traffic); differences of two
  // readings measure what lay between them.
  const Traffic& traffic() const { return traffic_; }

 private:
  // Counts one operation (only the thread that calls MPI does: MPI_THREAD_FUNNELED).
  void tally(std::uint64_t messages, std::uint64_t sent, std::uint64_t received) const {
    if (size_ > 1) traffic_ += Traffic{1, messages, sent, received};
  }
  mutable Traffic traffic_;
  Communicator() = default;
  friend class MpiSession;
  int rank_ = 0;
  int size_ = 1;
  bool mpi_ = false;
};

class MpiSession {
 public:
  // Initialises MPI when the build has it and a launcher started this process.
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  // Whether this build was compiled with MPI (SWIRL_MPI), and which library.
  static bool built_with_mpi();
  static const char* library_version();
};

}  // namespace swirl::dist
