// SPDX-License-Identifier: MIT
#include "distributed/communicator.hpp"

#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#ifdef DOMEL_HAVE_MPI
// MPI's C API only: not the C++ bindings (removed in MPI-3) that OpenMPI's
// and MPICH's mpi.h otherwise pull into a C++ translation unit
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace domel::platform {

#ifdef DOMEL_HAVE_MPI
namespace {
void check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}
bool mpi_running() {
  int init = 0, fin = 0;
  MPI_Initialized(&init);
  MPI_Finalized(&fin);
  return init && !fin;
}
}  // namespace

struct Communicator::Impl {
  MPI_Comm comm = MPI_COMM_WORLD;
  bool owned = false;  ///< made by split(): freed with the last copy
  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() {
    if (owned && mpi_running()) MPI_Comm_free(&comm);
  }
};
#else
struct Communicator::Impl {};
#endif

Communicator::Communicator() = default;

bool Communicator::built_with_mpi() {
#ifdef DOMEL_HAVE_MPI
  return true;
#else
  return false;
#endif
}

Communicator Communicator::world() {
  Communicator c;
#ifdef DOMEL_HAVE_MPI
  if (mpi_running()) {
    auto impl = std::make_shared<Impl>();
    check(MPI_Comm_rank(impl->comm, &c.rank_), "MPI_Comm_rank");
    check(MPI_Comm_size(impl->comm, &c.size_), "MPI_Comm_size");
    c.impl_ = std::move(impl);
  }
#endif
  return c;
}

Communicator Communicator::split(int colour) const {
  Communicator c;
#ifdef DOMEL_HAVE_MPI
  if (impl_) {
    auto impl = std::make_shared<Impl>();
    check(MPI_Comm_split(impl_->comm, colour, rank_, &impl->comm), "MPI_Comm_split");
    impl->owned = true;
    check(MPI_Comm_rank(impl->comm, &c.rank_), "MPI_Comm_rank");
    check(MPI_Comm_size(impl->comm, &c.size_), "MPI_Comm_size");
    c.impl_ = std::move(impl);
  }
#else
  (void)colour;
#endif
  return c;
}

void Communicator::sum(std::vector<std::uint64_t>& v) const {
  if (!impl_ || v.empty()) return;
#ifdef DOMEL_HAVE_MPI
  check(MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_UINT64_T, MPI_SUM, impl_->comm),
        "MPI_Allreduce");
#endif
}

std::vector<std::vector<char>> Communicator::all_to_all(const std::vector<std::vector<char>>& send) const {
  if (send.size() != static_cast<std::size_t>(size_))
    throw std::invalid_argument("Communicator::all_to_all: one buffer per rank expected");
  if (!impl_) return send;
  std::vector<std::vector<char>> recv(static_cast<std::size_t>(size_));
#ifdef DOMEL_HAVE_MPI
  const auto n = static_cast<std::size_t>(size_);
  // counts first (as 64-bit, so that no buffer size overflows an int unseen)
  std::vector<std::uint64_t> scount(n), rcount(n);
  for (std::size_t r = 0; r < n; ++r) scount[r] = send[r].size();
  check(MPI_Alltoall(scount.data(), 1, MPI_UINT64_T, rcount.data(), 1, MPI_UINT64_T, impl_->comm), "MPI_Alltoall");
  std::vector<int> sc(n), sd(n), rc(n), rd(n);
  std::uint64_t stotal = 0, rtotal = 0;
  for (std::size_t r = 0; r < n; ++r) {
    sd[r] = static_cast<int>(stotal);
    rd[r] = static_cast<int>(rtotal);
    sc[r] = static_cast<int>(scount[r]);
    rc[r] = static_cast<int>(rcount[r]);
    stotal += scount[r];
    rtotal += rcount[r];
  }
  if (stotal > static_cast<std::uint64_t>(INT32_MAX) || rtotal > static_cast<std::uint64_t>(INT32_MAX))
    throw std::runtime_error("MPI: an exchange of more than 2 GiB in one step");
  std::vector<char> sbuf(stotal), rbuf(rtotal);
  for (std::size_t r = 0; r < n; ++r) std::copy(send[r].begin(), send[r].end(), sbuf.begin() + sd[r]);
  check(MPI_Alltoallv(sbuf.data(), sc.data(), sd.data(), MPI_CHAR, rbuf.data(), rc.data(), rd.data(), MPI_CHAR,
                      impl_->comm),
        "MPI_Alltoallv");
  for (std::size_t r = 0; r < n; ++r) recv[r].assign(rbuf.begin() + rd[r], rbuf.begin() + rd[r] + rc[r]);
#endif
  return recv;
}

std::vector<std::vector<char>> Communicator::all_gather(const std::vector<char>& mine) const {
  return all_to_all(std::vector<std::vector<char>>(static_cast<std::size_t>(size_), mine));
}

double Communicator::max(double x) const {
  if (!impl_) return x;
  std::vector<char> mine(sizeof(double));
  std::memcpy(mine.data(), &x, sizeof(double));
  double out = x;
  for (const auto& b : all_gather(mine)) {
    double v = 0.0;
    std::memcpy(&v, b.data(), sizeof(double));
    out = std::max(out, v);
  }
  return out;
}

void Communicator::abort(int code) const {
#ifdef DOMEL_HAVE_MPI
  if (impl_) MPI_Abort(impl_->comm, code);
#endif
  std::exit(code);
}

bool Communicator::launched_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(v) != nullptr) return true;
  return false;
}

MpiSession::MpiSession(int* argc, char*** argv, bool use) {
#ifdef DOMEL_HAVE_MPI
  if (use && !mpi_running()) {
    // threads inside each rank; only the main thread calls MPI
    int provided = 0;
    check(MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
    if (provided < MPI_THREAD_FUNNELED)
      std::fprintf(stderr, "domel: this MPI library does not support threads inside a rank (MPI_THREAD_FUNNELED); "
                           "run with --threads 1\n");
    initialised_ = true;
  }
#else
  (void)argc;
  (void)argv;
  (void)use;
#endif
}

MpiSession::~MpiSession() {
#ifdef DOMEL_HAVE_MPI
  if (initialised_) MPI_Finalize();
#endif
}

}  // namespace domel::platform
