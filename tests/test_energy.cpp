// Energy balance over the whole El Centro record: input work = stored energy
// + frame damping + contact dissipation, for every device and contact law.
#include <gtest/gtest.h>

#include <tuple>

#include "support.hpp"
#include "vines/build/build_model.hpp"
#include "vines/step/sim.hpp"

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

// E_e by the Lyapunov split (telescoped boundary terms, a linear form per
// step) against the direct Van Loan step integral summed step by step, on the
// bare frame over El Centro: with damping (split used) and without (the split
// is refused and the loop integrates directly).
namespace {

using namespace vines;

double direct_elastic_energy(const Model<double, 10, NoDevice>& m, const std::vector<double>& a) {
  using VecX = Model<double, 10, NoDevice>::VecX;
  VecX z = VecX::Zero();
  double e = 0;
  for (std::size_t k = 1; k < a.size(); ++k) {
    e += m.strain_step.eval(z, a[k - 1], a[k]);
    m.lti.step(z, a[k - 1], a[k]);
  }
  return e;
}

TEST(ElasticEnergy, LyapunovSplitMatchesTheDirectIntegral) {
  const std::vector<double> a = test::elcentro(50.0);
  for (const double c_k : {0.0129, 0.0}) {
    SceneParams p = test::paper_scene(DeviceKind::kNone, ContactLaw::kKuwabara, 50.0);
    p.frame.stiffness_damping_s = c_k;
    static Model<double, 10, NoDevice> m;
    static Data<double, 10, NoDevice> d;
    ASSERT_TRUE(build_model(p, &m).ok());
    EXPECT_EQ(m.ee_lyapunov, c_k > 0.0);
    init(m, d, a[0]);
    for (std::size_t k = 1; k < a.size(); ++k) step(m, d, a[k]);
    const double direct = direct_elastic_energy(m, a);
    EXPECT_GT(direct, 0.0);
    EXPECT_NEAR(elastic_energy(m, d) / direct, 1.0, 1e-12) << "c_k = " << c_k;
  }
}

}  // namespace
