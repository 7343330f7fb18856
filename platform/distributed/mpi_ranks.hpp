// SPDX-License-Identifier: MIT
// The RunRanks of a run under mpirun (loop/ranks.hpp): the ranks of
// MPI_COMM_WORLD, each subdomain spread by distribute() (subdomain_ranks.hpp).
#pragma once

#include "distributed/communicator.hpp"
#include "distributed/subdomain_ranks.hpp"
#include "loop/ranks.hpp"

#include <utility>
#include <vector>

namespace domel::platform {

class MpiRunRanks final : public RunRanks {
 public:
  explicit MpiRunRanks(Communicator comm) : comm_(std::move(comm)) {}
  int rank() const override { return comm_.rank(); }
  int size() const override { return comm_.size(); }
  std::string on_each() const override { return " on each of " + std::to_string(comm_.size()) + " ranks"; }
  void distribute(Subdomain& sd, int first = 0, int count = 0) override;
  GatheredParticles gather(Subdomain& sd, bool everywhere = false) override;
  std::vector<std::vector<char>> all_gather(const std::vector<char>& mine) override { return comm_.all_gather(mine); }
  std::vector<std::vector<char>> gather_to_root(const std::vector<char>& mine) override {
    std::vector<std::vector<char>> send(static_cast<std::size_t>(comm_.size()));
    send[0] = mine;
    auto recv = comm_.all_to_all(send);
    if (comm_.rank() != 0) recv.clear();
    return recv;
  }
  void sum(std::vector<std::uint64_t>& v) override { comm_.sum(v); }
  double max(double x) override { return comm_.max(x); }
  nlohmann::json traffic(const Subdomain& sd) override;

 private:
  Communicator comm_;
  std::vector<std::pair<const Subdomain*, const SubdomainRanks*>> spread_;  ///< distribute()'s exchanges (here)
  std::vector<std::pair<const Subdomain*, int>> group_size_;  ///< the ranks each subdomain was spread over
};

}  // namespace domel::platform
