// SPDX-License-Identifier: MIT
// The MPI tests' main: MPI around GoogleTest, one report (the other ranks
// print only failures).
#include "distributed/communicator.hpp"

#include <gtest/gtest.h>

int main(int argc, char** argv) {
  domel::platform::MpiSession mpi(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  if (domel::platform::Communicator::world().rank() != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
