// SPDX-License-Identifier: MIT
// The levels' rank groups (subdomains[].rank_share, loop/ranks.hpp):
// consecutive groups that cover the ranks, sized in proportion to the shares
// by largest remainders, at least one rank each.
#include "loop/ranks.hpp"

#include <gtest/gtest.h>

namespace dp = domel::platform;

namespace {

std::vector<int> counts(const std::vector<dp::RankGroup>& g) {
  std::vector<int> c;
  int next = 0;
  for (const auto& x : g) {
    EXPECT_EQ(x.first, next) << "groups are consecutive";
    next += x.count;
    c.push_back(x.count);
  }
  return c;
}

}  // namespace

TEST(RankGroups, EqualSharesSplitEvenlyAndTheRemainderGoesToTheFirst) {
  EXPECT_EQ(counts(dp::rank_groups({1, 1}, 2)), (std::vector<int>{1, 1}));
  EXPECT_EQ(counts(dp::rank_groups({1, 1}, 4)), (std::vector<int>{2, 2}));
  EXPECT_EQ(counts(dp::rank_groups({1, 1}, 5)), (std::vector<int>{3, 2}));  // remainders 0.5, 0.5: the earlier
  EXPECT_EQ(counts(dp::rank_groups({1, 1, 1}, 4)), (std::vector<int>{2, 1, 1}));
}

TEST(RankGroups, SharesAreProportionsByLargestRemainders) {
  EXPECT_EQ(counts(dp::rank_groups({1, 3}, 4)), (std::vector<int>{1, 3}));
  EXPECT_EQ(counts(dp::rank_groups({1, 3}, 8)), (std::vector<int>{2, 6}));
  // quotas 10 * (0.2, 0.3, 0.5) = 2, 3, 5
  EXPECT_EQ(counts(dp::rank_groups({0.2, 0.3, 0.5}, 10)), (std::vector<int>{2, 3, 5}));
  // quotas 7 * (1, 2, 4) / 7 = 1, 2, 4
  EXPECT_EQ(counts(dp::rank_groups({1, 2, 4}, 7)), (std::vector<int>{1, 2, 4}));
  // quotas 5 * (1, 1, 2) / 4 = 1.25, 1.25, 2.5: floors 1, 1, 2, the last remainder is the largest
  EXPECT_EQ(counts(dp::rank_groups({1, 1, 2}, 5)), (std::vector<int>{1, 1, 3}));
}

TEST(RankGroups, EveryGroupHasARankEvenForATinyShare) {
  // quotas 2 * (0.001, 0.999) = 0.002, 1.998: the first is raised to one rank
  EXPECT_EQ(counts(dp::rank_groups({0.001, 0.999}, 2)), (std::vector<int>{1, 1}));
  // quotas 3 * (0.1, 0.1, 10) / 10.2 = 0.03, 0.03, 2.94: two raised to one rank, the largest gives one back
  EXPECT_EQ(counts(dp::rank_groups({0.1, 0.1, 10}, 3)), (std::vector<int>{1, 1, 1}));
  EXPECT_EQ(counts(dp::rank_groups({0.01, 1, 1}, 3)), (std::vector<int>{1, 1, 1}));
  EXPECT_EQ(counts(dp::rank_groups({0.01, 1, 1}, 4)), (std::vector<int>{1, 2, 1}));
}
