// SPDX-License-Identifier: MIT
// The ranks of a distributed run (issue 19): who am I, how many are we, and
// the few collectives the decomposition and the particle exchange need.
// Built on MPI's C API where domel is built with MPI (DOMEL_HAVE_MPI) and the
// process was started under mpirun; otherwise one rank, and every collective
// is the identity. mpi.h stays in communicator.cpp: nothing else includes it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace domel::platform {

class Communicator {
 public:
  /// One rank, no MPI.
  Communicator();
  /// MPI_COMM_WORLD when MPI is initialised (MpiSession), else one rank.
  static Communicator world();
  /// Whether this build has MPI at all.
  static bool built_with_mpi();

  int rank() const { return rank_; }
  int size() const { return size_; }
  /// The ranks of this communicator that passed the same `colour`, in the
  /// order they have here (MPI_Comm_split). Collective.
  Communicator split(int colour) const;

  /// Element-wise sums over the ranks, in place. Integers: exact, so the
  /// result does not depend on how the values are spread over the ranks.
  void sum(std::vector<std::uint64_t>& v) const;
  /// send[r] goes to rank r; returns what each rank sent here, by rank.
  std::vector<std::vector<char>> all_to_all(const std::vector<std::vector<char>>& send) const;
  /// Every rank's bytes, on every rank, by rank.
  std::vector<std::vector<char>> all_gather(const std::vector<char>& mine) const;
  /// The largest x over the ranks.
  double max(double x) const;
  /// End every rank of the run now with exit status `code` (MPI_Abort): a
  /// failure on one rank must not leave the others waiting in a collective.
  /// Without MPI, exits this process.
  [[noreturn]] void abort(int code) const;
  /// Whether this process was started by an MPI launcher (mpirun sets
  /// OMPI_COMM_WORLD_SIZE, Hydra PMI_SIZE): only then does a program that
  /// may run alone initialise MPI.
  static bool launched_by_mpirun();

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;  ///< null: one rank without MPI
  int rank_ = 0, size_ = 1;
};

/// MPI_Init / MPI_Finalize around a scope (one per process). Without MPI in
/// the build, or when `use` is false, it does nothing.
class MpiSession {
 public:
  MpiSession(int* argc, char*** argv, bool use = true);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

 private:
  bool initialised_ = false;
};

}  // namespace domel::platform
