// The convergence family's transformations keep the physics: a member in
// another amplitude unit responds with the same amplitudes times lambda, one
// in another time unit jumps at the same frequencies times s.
#include "dwellfit/estimator/studies/convergence_family.h"

#include <cmath>
#include <string>
#include <vector>

#include "gtest/gtest.h"

namespace dwellfit {
namespace {

const FamilyMember& Find(const std::vector<FamilyMember>& family, const std::string& name) {
  for (const FamilyMember& member : family) {
    if (member.name == name) return member;
  }
  ADD_FAILURE() << "no member " << name;
  return family.front();
}

TEST(ConvergenceFamily, UnitsChangeNumbersNotPhysics) {
  const std::vector<FamilyMember> family = ConvergenceFamily();
  EXPECT_GE(family.size(), 50u);
  for (const std::string base : {"thesis", "softening"}) {
    const std::vector<Sweep> reference = SimulateDwells(Find(family, base + " a*1 all-free").plan);
    const std::vector<Sweep> small = SimulateDwells(Find(family, base + " a*1e-06 all-free").plan);
    const std::vector<Sweep> fast = SimulateDwells(Find(family, base + " t/100 all-free").plan);
    ASSERT_EQ(reference.size(), small.size());
    ASSERT_EQ(reference.size(), fast.size());
    int jumps = 0;
    for (size_t s = 0; s < reference.size(); ++s) {
      ASSERT_EQ(reference[s].points.size(), small[s].points.size());
      for (size_t i = 0; i < reference[s].points.size(); ++i) {
        EXPECT_NEAR(small[s].points[i].amplitude / reference[s].points[i].amplitude, 1e-6, 1e-15);
        EXPECT_NEAR(fast[s].points[i].amplitude / reference[s].points[i].amplitude, 1.0, 1e-9);
      }
      ASSERT_EQ(reference[s].jumps.size(), fast[s].jumps.size());
      for (size_t j = 0; j < reference[s].jumps.size(); ++j, ++jumps) {
        const double scale = reference[s].kind == SweepKind::kFrequency ? 100.0 : 1.0;
        EXPECT_NEAR(fast[s].jumps[j].centre() / reference[s].jumps[j].centre(), scale,
                    1e-9 * scale);
      }
    }
    EXPECT_EQ(jumps, 4) << base << ": both sweeps jump, up and down";
  }
}

}  // namespace
}  // namespace dwellfit
