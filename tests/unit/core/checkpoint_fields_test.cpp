// SPDX-License-Identifier: MIT
// Guards the one-list checkpoint description (core/archive.hpp,
// CheckpointFields): a class that names its fields once, in one function,
// saves and loads them through the same list, so a round trip restores
// every value; and a checkpoint written by a version of the class whose
// list differs -- two fields swapped, one dropped, one added -- is refused
// with a ConfigError naming the part's ".fields" section and the field,
// before any value is read into the object. Cost: microseconds.
#include <gtest/gtest.h>

#include "core/archive.hpp"
#include "core/error.hpp"

#include <string>
#include <vector>

namespace {

namespace dp = domel::platform;

/// The throw-away class: a count, a flag, a time series and a label; `order`
/// chooses the list's version (0: as written, 1: count and flag swapped, 2:
/// the label dropped, 3: a field added at the end).
struct Throwaway {
  std::uint64_t count = 0;
  bool flag = false;
  std::vector<double> series;
  std::string label;
  double added = 0;
  int order = 0;

  void fields(dp::CheckpointFields& f) {
    if (order == 1) {
      f("flag", flag);
      f("count", count);
    } else {
      f("count", count);
      f("flag", flag);
    }
    f("series", series);
    if (order != 2) f("label", label);
    if (order == 3) f("added", added);
  }
};

/// The checkpoint's bytes with `t` saved under "part/".
std::string saved(Throwaway& t) {
  dp::ArchiveWriter w;
  dp::save_fields(w, "part/", [&](dp::CheckpointFields& f) { t.fields(f); });
  return w.serialize("{}");
}

TEST(CheckpointFields, OneListSavesAndLoadsEveryField) {
  Throwaway a{42, true, {1.5, -2.25, 1e-300}, "silo"};
  const std::string bytes = saved(a);
  Throwaway b;
  const dp::ArchiveReader r(bytes, "test.ckpt");
  dp::load_fields(r, "part/", [&](dp::CheckpointFields& f) { b.fields(f); });
  EXPECT_EQ(b.count, 42u);
  EXPECT_TRUE(b.flag);
  EXPECT_EQ(b.series, a.series);
  EXPECT_EQ(b.label, "silo");
  EXPECT_TRUE(r.has("part/.fields"));
}

TEST(CheckpointFields, AListInAnotherOrderOrWithAFieldMoreOrLessIsRefusedNamingTheField) {
  Throwaway a{42, true, {1.5}, "silo"};
  const std::string bytes = saved(a);
  const dp::ArchiveReader r(bytes, "test.ckpt");
  const struct {
    int order;
    const char* names;  ///< what the message must name
  } cases[] = {{1, "'count u64' as field 1 where this build reads 'flag u8'"},
               {2, "'label bytes' as field 4, which this build does not read"},
               {3, "lists 4 fields; this build reads 'added f64' as field 5"}};
  for (const auto& c : cases) {
    Throwaway b;
    b.order = c.order;
    try {
      dp::load_fields(r, "part/", [&](dp::CheckpointFields& f) { b.fields(f); });
      ADD_FAILURE() << "order " << c.order << ": a changed field list was accepted";
    } catch (const dp::ConfigError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("test.ckpt"), std::string::npos) << what;
      EXPECT_NE(what.find("part/.fields"), std::string::npos) << what;
      EXPECT_NE(what.find(c.names), std::string::npos) << what;
    }
    if (c.order == 1) EXPECT_EQ(b.count, 0u) << "nothing was read into the object before the refusal";
  }
}

}  // namespace
