// SPDX-License-Identifier: MIT
#include "distributed/decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace domel::platform {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

/// The bin of value v in [lo, hi) split into bins parts (clamped).
int bin_of(double v, double lo, double hi, int bins) {
  if (!(hi > lo)) return 0;
  const double u = std::floor((v - lo) / (hi - lo) * bins);
  return static_cast<int>(std::clamp(u, 0.0, static_cast<double>(bins - 1)));
}
double edge(double lo, double hi, int k, int bins) { return lo + (hi - lo) * k / bins; }
}  // namespace

double Region::distance(const double p[3]) const {
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double d = std::max({lo[a] - p[a], 0.0, p[a] - hi[a]});
    d2 += d * d;
  }
  return std::sqrt(d2);
}

Decomposition::Decomposition() {
  Node root;
  for (int a = 0; a < 3; ++a) {
    root.region.lo[a] = -kInf;
    root.region.hi[a] = kInf;
  }
  nodes_.push_back(root);
  leaf_.push_back(0);
}

Decomposition Decomposition::bisect(const Region& extent, int parts, const double* x, const double* y,
                                    const double* z, const std::uint64_t* cost, std::size_t n,
                                    const Communicator& comm) {
  if (parts < 1) throw std::invalid_argument("Decomposition::bisect: at least one part");
  for (int a = 0; a < 3; ++a)
    if (!(extent.hi[a] >= extent.lo[a]) || !std::isfinite(extent.lo[a]) || !std::isfinite(extent.hi[a]))
      throw std::invalid_argument("Decomposition::bisect: the extent must be a finite box");
  Decomposition d;
  d.nodes_[0].count = parts;
  // per node, its region clipped to the extent: where its histograms live
  std::vector<Region> span{extent};
  std::vector<std::size_t> at(n, 0);  // each point's node
  std::vector<std::size_t> open;
  if (parts > 1) open.push_back(0);
  const double* pos[3] = {x, y, z};
  constexpr int B = kBins;
  while (!open.empty()) {
    // slot of each open node, and its axis: its span's longest
    std::vector<long> slot(d.nodes_.size(), -1);
    for (std::size_t s = 0; s < open.size(); ++s) {
      slot[open[s]] = static_cast<long>(s);
      const Region& sp = span[open[s]];
      int axis = 0;
      for (int a = 1; a < 3; ++a)
        if (sp.hi[a] - sp.lo[a] > sp.hi[axis] - sp.lo[axis]) axis = a;
      d.nodes_[open[s]].axis = axis;
    }
    // pass 1: coarse histograms of every open node, summed over the ranks
    std::vector<std::uint64_t> hist(open.size() * B, 0);
    for (std::size_t k = 0; k < n; ++k) {
      const long s = slot[at[k]];
      if (s < 0) continue;
      const Node& nd = d.nodes_[at[k]];
      hist[static_cast<std::size_t>(s) * B +
           static_cast<std::size_t>(bin_of(pos[nd.axis][k], span[at[k]].lo[nd.axis], span[at[k]].hi[nd.axis], B))] +=
          cost[k];
    }
    comm.sum(hist);
    // the coarse bin where the left share is reached, and the cost below it
    std::vector<int> coarse(open.size(), 0);
    std::vector<std::uint64_t> below(open.size(), 0), total(open.size(), 0), goal_num(open.size(), 0);
    for (std::size_t s = 0; s < open.size(); ++s) {
      const Node& nd = d.nodes_[open[s]];
      for (int b = 0; b < B; ++b) total[s] += hist[s * B + static_cast<std::size_t>(b)];
      // left share: cost_left * count >= total * (count / 2), in integers
      const auto left = static_cast<std::uint64_t>(nd.count / 2);
      goal_num[s] = total[s] * left;
      std::uint64_t cum = 0;
      int b = 0;
      for (; b < B; ++b) {
        const std::uint64_t next = cum + hist[s * B + static_cast<std::size_t>(b)];
        if (next * static_cast<std::uint64_t>(nd.count) >= goal_num[s]) break;
        cum = next;
      }
      coarse[s] = std::min(b, B - 1);
      below[s] = cum;
    }
    // pass 2: that bin in kBins finer bins
    std::vector<std::uint64_t> fine(open.size() * B, 0);
    for (std::size_t k = 0; k < n; ++k) {
      const long s = slot[at[k]];
      if (s < 0) continue;
      const Node& nd = d.nodes_[at[k]];
      const double lo = span[at[k]].lo[nd.axis], hi = span[at[k]].hi[nd.axis];
      const double v = pos[nd.axis][k];
      const int cb = coarse[static_cast<std::size_t>(s)];
      if (bin_of(v, lo, hi, B) != cb) continue;
      fine[static_cast<std::size_t>(s) * B +
           static_cast<std::size_t>(bin_of(v, edge(lo, hi, cb, B), edge(lo, hi, cb + 1, B), B))] += cost[k];
    }
    comm.sum(fine);
    std::vector<std::size_t> next_open;
    for (std::size_t s = 0; s < open.size(); ++s) {
      const std::size_t id = open[s];
      const int axis = d.nodes_[id].axis;
      const double lo = span[id].lo[axis], hi = span[id].hi[axis];
      const int count = d.nodes_[id].count;
      double cut;
      if (total[s] == 0) {
        cut = lo + (hi - lo) * (count / 2) / count;  // nothing to weigh: by volume
      } else {
        const double e0 = edge(lo, hi, coarse[s], B), e1 = edge(lo, hi, coarse[s] + 1, B);
        std::uint64_t cum = below[s];
        int f = 0;
        for (; f < B; ++f) {
          cum += fine[s * B + static_cast<std::size_t>(f)];
          if (cum * static_cast<std::uint64_t>(count) >= goal_num[s]) break;
        }
        cut = edge(e0, e1, std::min(f, B - 1) + 1, B);
      }
      Node l = d.nodes_[id], r = d.nodes_[id];
      l.axis = r.axis = -1;
      l.count = count / 2;
      r.first = l.first + l.count;
      r.count = count - l.count;
      l.region.hi[axis] = cut;
      r.region.lo[axis] = cut;
      Region ls = span[id], rs = span[id];
      ls.hi[axis] = cut;
      rs.lo[axis] = cut;
      d.nodes_[id].cut = cut;
      d.nodes_[id].left = static_cast<int>(d.nodes_.size());
      d.nodes_.push_back(l);
      span.push_back(ls);
      d.nodes_[id].right = static_cast<int>(d.nodes_.size());
      d.nodes_.push_back(r);
      span.push_back(rs);
      if (l.count > 1) next_open.push_back(static_cast<std::size_t>(d.nodes_[id].left));
      if (r.count > 1) next_open.push_back(static_cast<std::size_t>(d.nodes_[id].right));
    }
    for (std::size_t k = 0; k < n; ++k) {
      const Node& nd = d.nodes_[at[k]];
      if (nd.axis < 0 || nd.left < 0) continue;
      at[k] = static_cast<std::size_t>(pos[nd.axis][k] < nd.cut ? nd.left : nd.right);
    }
    open = std::move(next_open);
  }
  d.leaf_.assign(static_cast<std::size_t>(parts), 0);
  for (std::size_t id = 0; id < d.nodes_.size(); ++id)
    if (d.nodes_[id].left < 0) d.leaf_[static_cast<std::size_t>(d.nodes_[id].first)] = id;
  return d;
}

int Decomposition::owner(const double p[3]) const {
  std::size_t id = 0;
  while (nodes_[id].left >= 0) {
    const Node& nd = nodes_[id];
    id = static_cast<std::size_t>(p[nd.axis] < nd.cut ? nd.left : nd.right);
  }
  return nodes_[id].first;
}

void Decomposition::parts_within(const double p[3], double cutoff, std::vector<int>& out,
                                 const PeriodicBox& box) const {
  out.clear();
  std::vector<std::size_t> stack{0};
  while (!stack.empty()) {
    const std::size_t id = stack.back();
    stack.pop_back();
    const Node& nd = nodes_[id];
    Region r = nd.region;
    for (int a = 0; a < 3; ++a)
      if (box.axis[a]) {
        r.lo[a] = std::max(r.lo[a], box.lo[a]);
        r.hi[a] = std::min(r.hi[a], box.hi[a]);
      }
    if (r.distance(p) > cutoff) continue;
    if (nd.left < 0) {
      out.push_back(nd.first);
    } else {
      stack.push_back(static_cast<std::size_t>(nd.right));
      stack.push_back(static_cast<std::size_t>(nd.left));
    }
  }
  std::sort(out.begin(), out.end());
}

}  // namespace domel::platform
