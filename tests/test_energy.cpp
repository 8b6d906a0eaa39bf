// Energy balance over the whole El Centro record: input work = stored energy
// + frame damping + contact dissipation, for every device and contact law.
#include <gtest/gtest.h>

#include <tuple>

#include "support.hpp"

namespace {

using namespace vines;

class Balance : public ::testing::TestWithParam<std::tuple<DeviceKind, ContactLaw>> {};

TEST_P(Balance, ResidualBelow1e6) {
  const auto [kind, law] = GetParam();
  const test::Outcome o = test::run(test::paper_scene(kind, law), test::elcentro(1000.0));
  const Ledger& l = o.totals.ledger;
  EXPECT_LT(l.relative_residual(), 1e-6);
  EXPECT_GT(l.input, 0.0);
  EXPECT_GT(l.damping, 0.0);
  if (kind == DeviceKind::kVines && law != ContactLaw::kHertz) EXPECT_GT(l.contact, 0.0);
  if (law == ContactLaw::kHertz) EXPECT_LT(std::abs(l.contact), 1e-9 * l.input);
}

// A device need not sit on the top floor.
TEST(BalanceOnAnotherFloor, VinesAndTmdOnFloorSix) {
  for (DeviceKind kind : {DeviceKind::kVines, DeviceKind::kTmd}) {
    SceneParams p = test::paper_scene(kind);
    p.device.floor = 6;
    const test::Outcome o = test::run(p, test::elcentro(1000.0));
    EXPECT_LT(o.totals.ledger.relative_residual(), 1e-6);
  }
}

INSTANTIATE_TEST_SUITE_P(
    AllDevices, Balance,
    ::testing::Values(std::make_tuple(DeviceKind::kNone, ContactLaw::kKuwabara),
                      std::make_tuple(DeviceKind::kTmd, ContactLaw::kKuwabara),
                      std::make_tuple(DeviceKind::kVines, ContactLaw::kHertz),
                      std::make_tuple(DeviceKind::kVines, ContactLaw::kTsuji),
                      std::make_tuple(DeviceKind::kVines, ContactLaw::kKuwabara),
                      std::make_tuple(DeviceKind::kVines, ContactLaw::kRestitution)));

}  // namespace
