// SPDX-License-Identifier: MIT
// The RunRanks of a run under mpirun (scheduler/run_ranks.hpp): the ranks of
// MPI_COMM_WORLD, each subdomain spread by distribute() (subdomain_ranks.hpp).
#pragma once

#include "distributed/communicator.hpp"
#include "scheduler/run_ranks.hpp"

namespace domel::platform {

class MpiRunRanks final : public RunRanks {
 public:
  explicit MpiRunRanks(Communicator comm) : comm_(std::move(comm)) {}
  int rank() const override { return comm_.rank(); }
  int size() const override { return comm_.size(); }
  void distribute(Subdomain& sd) override;
  ParticleStore gather(Subdomain& sd) override;
  void sum(std::vector<std::uint64_t>& v) override { comm_.sum(v); }
  double max(double x) override { return comm_.max(x); }

 private:
  Communicator comm_;
};

}  // namespace domel::platform
