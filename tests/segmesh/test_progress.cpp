// The progress adapters: a stretch of a step (SubProgress) and a step shared by weighted parts
// (PartsProgress): weighted means, no step backwards on late updates, cancellation passed through.
#include "segmesh/progress.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "segmesh/error.hpp"

namespace segmesh {
namespace {

struct Log : Progress {
  std::vector<double> fractions;
  bool cancel = false;
  void update(double f) override { fractions.push_back(f); }
  bool cancelled() const override { return cancel; }
};

TEST(SubProgress, MapsOntoItsStretchAndPassesCancellation) {
  Log log;
  SubProgress second_half(log, 0.5, 1.0);
  second_half.update(0);
  second_half.update(0.5);
  second_half.update(1);
  EXPECT_EQ(log.fractions, (std::vector<double>{0.5, 0.75, 1.0}));
  EXPECT_FALSE(second_half.cancelled());
  log.cancel = true;
  EXPECT_THROW(throw_if_cancelled(second_half), Cancelled);
}

TEST(PartsProgress, ReportsTheWeightedMeanOfItsParts) {
  Log log;
  PartsProgress parts(log, {3, 1});
  parts.part(0).update(0.5);  // 1.5 of 4
  EXPECT_DOUBLE_EQ(log.fractions.back(), 0.375);
  parts.part(1).update(1.0);  // 2.5 of 4
  EXPECT_DOUBLE_EQ(log.fractions.back(), 0.625);
  // A late, smaller update of part 0 does not move the step back (and reports nothing).
  const size_t reported = log.fractions.size();
  parts.part(0).update(0.25);
  EXPECT_EQ(log.fractions.size(), reported);
  parts.done(0);
  EXPECT_DOUBLE_EQ(log.fractions.back(), 1.0);
  // Out of range fractions are clamped; parts cancel with the step.
  parts.part(1).update(7);
  EXPECT_LE(log.fractions.back(), 1.0);
  EXPECT_FALSE(parts.part(1).cancelled());
  log.cancel = true;
  EXPECT_TRUE(parts.part(1).cancelled());
}

TEST(PartsProgress, PartsWithoutWeightStillFinish) {
  Log log;
  PartsProgress parts(log, {0, 0});
  parts.done(0);
  EXPECT_EQ(log.fractions.back(), 1.0);
}

}  // namespace
}  // namespace segmesh
