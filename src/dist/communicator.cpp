// The communicator over MPI (SWIRL_WITH_MPI, set by CMake on this file's
// library when SWIRL_MPI is on) or over a single rank.
#include "swirl/dist/communicator.hpp"
#include "mpi_handle.hpp"

#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#if SWIRL_WITH_MPI
#include <mpi.h>
#endif

namespace swirl::dist {

namespace {

Communicator*& world_instance() {
  static Communicator* instance = nullptr;
  return instance;
}

#if SWIRL_WITH_MPI
void check(int status, const char* what) {
  if (status != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

int as_count(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw std::runtime_error(std::string("MPI: ") + what + ": more than 2^31 - 1 bytes in one message");
  return static_cast<int>(n);
}

bool launched_by_mpirun() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}
#endif

}  // namespace

const Communicator& Communicator::world() {
  static const Communicator single_rank;
  const Communicator* w = world_instance();
  return w != nullptr ? *w : single_rank;
}

#if SWIRL_WITH_MPI
namespace {
// One in-place allreduce over every rank: sum, min and max are this call with
// their own type and operation.
void allreduce_in_place(void* values, std::size_t count, MPI_Datatype type, MPI_Op op, const char* name) {
  check(MPI_Allreduce(MPI_IN_PLACE, values, as_count(count, name), type, op, MPI_COMM_WORLD),
        (std::string("MPI_Allreduce(") + name + ")").c_str());
}
}  // namespace
#endif

void Communicator::sum(std::span<std::uint64_t> values) const {
#if SWIRL_WITH_MPI
  if (mpi_ && !values.empty()) {
    allreduce_in_place(values.data(), values.size(), MPI_UINT64_T, MPI_SUM, "sum");
    tally(1, values.size_bytes(), values.size_bytes());
  }
#else
  (void)values;
#endif
}

void Communicator::min(std::span<double> values) const {
#if SWIRL_WITH_MPI
  if (mpi_ && !values.empty()) {
    allreduce_in_place(values.data(), values.size(), MPI_DOUBLE, MPI_MIN, "min");
    tally(1, values.size_bytes(), values.size_bytes());
  }
#else
  (void)values;
#endif
}

void Communicator::max(std::span<double> values) const {
#if SWIRL_WITH_MPI
  if (mpi_ && !values.empty()) {
    allreduce_in_place(values.data(), values.size(), MPI_DOUBLE, MPI_MAX, "max");
    tally(1, values.size_bytes(), values.size_bytes());
  }
#else
  (void)values;
#endif
}

std::uint64_t Communicator::sum(std::uint64_t value) const {
  sum(std::span<std::uint64_t>(&value, 1));
  return value;
}

std::uint64_t Communicator::exclusive_prefix_sum(std::uint64_t value) const {
  const std::vector<std::uint64_t> all = all_gather(value);
  std::uint64_t below = 0;
  for (int r = 0; r < rank_; ++r) below += all[static_cast<std::size_t>(r)];
  return below;
}

std::vector<std::uint64_t> Communicator::all_gather(std::uint64_t value) const {
  std::vector<std::uint64_t> all(static_cast<std::size_t>(size_), value);
#if SWIRL_WITH_MPI
  if (mpi_) {
    check(MPI_Allgather(&value, 1, MPI_UINT64_T, all.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD), "MPI_Allgather");
    const auto others = std::uint64_t(size_ - 1);
    tally(others, others * sizeof(value), others * sizeof(value));
  }
#endif
  return all;
}

std::vector<Bytes> Communicator::all_to_all(const std::vector<Bytes>& send) const {
  if (send.size() != static_cast<std::size_t>(size_))
    throw std::invalid_argument("all_to_all: one buffer per rank is needed");
#if SWIRL_WITH_MPI
  if (mpi_) {
    const auto n = static_cast<std::size_t>(size_);
    std::vector<int> send_counts(n), recv_counts(n), send_offsets(n), recv_offsets(n);
    Bytes send_flat;
    for (std::size_t d = 0; d < n; ++d) {
      send_counts[d] = as_count(send[d].size(), "all_to_all");
      send_offsets[d] = as_count(send_flat.size(), "all_to_all");
      send_flat.insert(send_flat.end(), send[d].begin(), send[d].end());
    }
    check(MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, MPI_COMM_WORLD),
          "MPI_Alltoall(counts)");
    std::size_t total = 0;
    for (std::size_t s = 0; s < n; ++s) {
      recv_offsets[s] = as_count(total, "all_to_all");
      total += static_cast<std::size_t>(recv_counts[s]);
    }
    Bytes recv_flat(total);
    check(MPI_Alltoallv(send_flat.data(), send_counts.data(), send_offsets.data(), MPI_BYTE, recv_flat.data(),
                        recv_counts.data(), recv_offsets.data(), MPI_BYTE, MPI_COMM_WORLD),
          "MPI_Alltoallv");
    std::vector<Bytes> received(n);
    std::uint64_t messages = 0, sent = 0, got = 0;
    for (std::size_t s = 0; s < n; ++s) {
      const auto begin = recv_flat.begin() + recv_offsets[s];
      received[s].assign(begin, begin + recv_counts[s]);
      if (s == static_cast<std::size_t>(rank_)) continue;
      messages += send[s].empty() ? 0 : 1;
      sent += send[s].size();
      got += received[s].size();
    }
    tally(messages, sent, got);
    return received;
  }
#endif
  return send;
}

std::vector<Bytes> Communicator::all_gather(const Bytes& mine) const {
#if SWIRL_WITH_MPI
  if (mpi_) {
    const auto n = static_cast<std::size_t>(size_);
    const int count = as_count(mine.size(), "all_gather");
    std::vector<int> counts(n), offsets(n);
    check(MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather(counts)");
    std::size_t total = 0;
    for (std::size_t s = 0; s < n; ++s) {
      offsets[s] = as_count(total, "all_gather");
      total += static_cast<std::size_t>(counts[s]);
    }
    Bytes flat(total);
    check(MPI_Allgatherv(mine.data(), count, MPI_BYTE, flat.data(), counts.data(), offsets.data(), MPI_BYTE,
                         MPI_COMM_WORLD),
          "MPI_Allgatherv");
    std::vector<Bytes> all(n);
    for (std::size_t s = 0; s < n; ++s) all[s].assign(flat.begin() + offsets[s], flat.begin() + offsets[s] + counts[s]);
    const auto others = std::uint64_t(size_ - 1);
    tally(others, others * mine.size(), total - mine.size());
    return all;
  }
#endif
  return {mine};
}

std::string Communicator::first_text(const std::string& mine) const {
  if (!distributed()) return mine;
  // No copy from an empty string's data (it may be null).
  const auto* first = reinterpret_cast<const std::byte*>(mine.data());
  const Bytes bytes = mine.empty() ? Bytes() : Bytes(first, first + mine.size());
  for (const Bytes& b : all_gather(bytes))
    if (!b.empty()) return std::string(reinterpret_cast<const char*>(b.data()), b.size());
  return {};
}

std::vector<Bytes> Communicator::gather_to_root(const Bytes& mine) const {
#if SWIRL_WITH_MPI
  if (mpi_) {
    const auto n = static_cast<std::size_t>(size_);
    const int count = as_count(mine.size(), "gather_to_root");
    std::vector<int> counts(n), offsets(n);
    check(MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD), "MPI_Gather(counts)");
    std::size_t total = 0;
    for (std::size_t s = 0; s < n; ++s) {
      offsets[s] = as_count(total, "gather_to_root");
      total += static_cast<std::size_t>(counts[s]);
    }
    Bytes flat(is_root() ? total : 0);
    check(MPI_Gatherv(mine.data(), count, MPI_BYTE, flat.data(), counts.data(), offsets.data(), MPI_BYTE, 0,
                      MPI_COMM_WORLD),
          "MPI_Gatherv");
    std::vector<Bytes> all;
    if (is_root()) {
      all.resize(n);
      for (std::size_t s = 0; s < n; ++s) all[s].assign(flat.begin() + offsets[s], flat.begin() + offsets[s] + counts[s]);
      tally(0, 0, total - mine.size());
    } else {
      tally(1, mine.size(), 0);
    }
    return all;
  }
#endif
  return {mine};
}

void Communicator::barrier() const {
#if SWIRL_WITH_MPI
  if (mpi_) {
    check(MPI_Barrier(MPI_COMM_WORLD), "MPI_Barrier");
    tally(0, 0, 0);
  }
#endif
}

void Communicator::abort(int exit_status) const {
#if SWIRL_WITH_MPI
  if (mpi_) MPI_Abort(MPI_COMM_WORLD, exit_status);
#endif
  std::exit(exit_status);
}

const void* detail::mpi_comm(const Communicator& comm) {
#if SWIRL_WITH_MPI
  static const MPI_Comm world = MPI_COMM_WORLD;  // what world() runs on
  if (comm.distributed()) return &world;
#else
  (void)comm;
#endif
  return nullptr;
}

MpiSession::MpiSession(int& argc, char**& argv) {
#if SWIRL_WITH_MPI
  if (!launched_by_mpirun() || world_instance() != nullptr) return;
  int provided = 0;
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  // Errors come back as codes (turned into exceptions above), not as aborts
  // inside MPI, so that the failing rank can say what failed before it ends the run.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  static Communicator world;
  MPI_Comm_rank(MPI_COMM_WORLD, &world.rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &world.size_);
  world.mpi_ = true;
  world_instance() = &world;
#else
  (void)argc;
  (void)argv;
#endif
}

MpiSession::~MpiSession() {
#if SWIRL_WITH_MPI
  if (world_instance() != nullptr) {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
    world_instance() = nullptr;
  }
#endif
}

bool MpiSession::built_with_mpi() { return SWIRL_WITH_MPI != 0; }

const char* MpiSession::library_version() {
#if SWIRL_WITH_MPI
  static char version[MPI_MAX_LIBRARY_VERSION_STRING] = {};
  if (version[0] == '\0') {
    int length = 0;
    MPI_Get_library_version(version, &length);
    for (int i = 0; i < length; ++i)
      if (version[i] == ',' || version[i] == '\n') {
        version[i] = '\0';
        break;
      }
  }
  return version;
#else
  return "none";
#endif
}

}  // namespace swirl::dist
