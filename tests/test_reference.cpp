// The reference integrators (sim_host/reference): against closed forms, the
// Hertz impact, their own convergence, the firmware loop, the stored
// data/reference files, the tuned DOP853 baseline (its right-hand side, its
// agreement with the stored references on the record's own points, its
// convergence), the CVODE baseline (or, built without it, its refusal), and
// bad input. test_reference_slow.cpp runs the whole El Centro records at 1 kHz.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "sim_host/bench/bench.hpp"
#include "sim_host/reference/ode.hpp"
#include "sim_host/reference/report.hpp"
#include "sim_host/reference/spec.hpp"
#include "sim_host/reference/truth.hpp"
#include "sim_host/reference/tuned_ode.hpp"
#include "sim_host/run/run.hpp"
#include "sim_host/scene/frame.hpp"
#include "sim_host/scene/scene.hpp"
#include "reference_support.hpp"
#include "support.hpp"
#include "vines/model/frame.hpp"

namespace {

using namespace vines;
using namespace vines::host;
using namespace vines::host::reference;
using LD = long double;

using test::rel;

// ---- the frame at run-time size equals the firmware's build_frame<10> ----

void expect_same_frame(const FrameParams& fp) {
  const Frame<10> f = build_frame<10>(fp);
  const HostFrame h = build_host_frame(fp);
  ASSERT_EQ(h.n, 10);
  const double ks = f.K.cwiseAbs().maxCoeff(), cs = f.C.cwiseAbs().maxCoeff();
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      EXPECT_NEAR(h.K_at(i, j), f.K(i, j), 1e-12 * ks) << i << "," << j;
      EXPECT_NEAR(h.C_at(i, j), f.C(i, j), 1e-12 * cs) << i << "," << j;
    }
  const Modal<10> md = modal_analysis(f);
  const HostModes hm = host_modes(h);
  for (int j = 0; j < 10; ++j) {
    EXPECT_NEAR(hm.omega[j], md.omega(j), 1e-12 * md.omega(j));
    EXPECT_NEAR(hm.m_eff[j], md.m_eff(j), 1e-9 * md.m_eff(0));
  }
}

TEST(ReferenceFrame, EqualsTheFirmwareFrameForEveryDampingRule) {
  FrameParams fp = test::paper_scene(DeviceKind::kNone).frame;
  expect_same_frame(fp);
  fp.stiffness_scale = 0.8;
  fp.damping = DampingRule::kRayleigh;
  expect_same_frame(fp);
  fp.damping = DampingRule::kModal;
  expect_same_frame(fp);
}

// ---- a 1-story frame against its closed form ----

struct Sdof {
  LD m, k, c, w, z, wd;
};

Sdof one_story(SceneParams* p) {
  p->frame = FrameParams{};
  p->frame.stories = 1;
  p->frame.mass_kg[0] = 1e5;
  p->frame.stiffness_n_per_m[0] = 4e6;
  p->frame.stiffness_damping_s = 0.0129;
  Sdof s{1e5L, 4e6L, 0.0129L * 4e6L, 0, 0, 0};
  s.w = std::sqrt(s.k / s.m);
  s.z = s.c / (2 * s.m * s.w);
  s.wd = s.w * std::sqrt(1 - s.z * s.z);
  return s;
}

// Exact response to a_g linear between samples, interval by interval: peak of
// |x| (at the zeros of v, by bisection on the closed form) and E_e (5-point
// Gauss-Legendre on panels of 5 ms, exact to rounding).
struct Closed {
  LD peak = 0, energy = 0;
};

Closed closed_form(const Sdof& s, const std::vector<double>& a, double rate) {
  Closed out;
  LD x0 = 0, v0 = 0;
  const LD h = 1.0L / rate;
  const LD r10 = std::sqrt(10.0L / 7.0L), r70 = std::sqrt(70.0L);
  const LD gx[5] = {0, -std::sqrt(5 - 2 * r10) / 3, std::sqrt(5 - 2 * r10) / 3, -std::sqrt(5 + 2 * r10) / 3,
                    std::sqrt(5 + 2 * r10) / 3};
  const LD gw[5] = {128.0L / 225, (322 + 13 * r70) / 900, (322 + 13 * r70) / 900, (322 - 13 * r70) / 900,
                    (322 - 13 * r70) / 900};
  for (std::size_t i = 0; i + 1 < a.size(); ++i) {
    const LD a0 = a[i], sl = (LD(a[i + 1]) - a[i]) * rate;
    // Particular solution of x'' + 2 z w x' + w^2 x = -(a0 + sl t), plus the free part.
    const LD xp0 = -a0 / (s.w * s.w) + 2 * s.z * sl / (s.w * s.w * s.w), vp = -sl / (s.w * s.w);
    const LD A = x0 - xp0, B = (v0 - vp + s.z * s.w * A) / s.wd;
    auto x = [&](LD t) {
      return xp0 + vp * t + std::exp(-s.z * s.w * t) * (A * std::cos(s.wd * t) + B * std::sin(s.wd * t));
    };
    auto v = [&](LD t) {
      const LD e = std::exp(-s.z * s.w * t), c = std::cos(s.wd * t), sn = std::sin(s.wd * t);
      return vp + e * (-s.z * s.w * (A * c + B * sn) + s.wd * (-A * sn + B * c));
    };
    // Panels of at most 5 ms: Gauss-Legendre and the sign test resolve them.
    const int panels = static_cast<int>(std::ceil(h / 0.005L));
    for (int k = 0; k < panels; ++k) {
      const LD t0 = h * k / panels, t1 = h * (k + 1) / panels, hp = t1 - t0;
      for (int q = 0; q < 5; ++q) {
        const LD xx = x(t0 + hp / 2 * (1 + gx[q]));
        out.energy += hp / 2 * gw[q] * 0.5L * s.k * xx * xx;
      }
      out.peak = std::max(out.peak, std::fabs(x(t1)));
      if ((v(t0) < 0) == (v(t1) < 0)) continue;
      LD lo = t0, hi = t1;
      for (int it = 0; it < 100; ++it) {
        const LD mid = (lo + hi) / 2;
        ((v(mid) < 0) == (v(lo) < 0) ? lo : hi) = mid;
      }
      out.peak = std::max(out.peak, std::fabs(x(lo)));
    }
    x0 = x(h);
    v0 = v(h);
  }
  return out;
}

TEST(ReferenceAnalytic, OneStoryUnderLinearGroundAcceleration) {
  SceneParams p;
  const Sdof s = one_story(&p);
  const std::vector<double> a = {0.5, -2.0};  // one ramp over 10 s
  const Closed c = closed_form(s, a, 0.1);
  const Result r = integrate(p, a, 0.1, Method::kReference, {});
  std::printf("[ measured ] peak rel err %.1e, E_e rel err %.1e\n", rel(r.peak_top, static_cast<double>(c.peak)),
              rel(r.elastic_energy, static_cast<double>(c.energy)));
  EXPECT_LT(rel(r.peak_top, static_cast<double>(c.peak)), 1e-12);
  EXPECT_LT(rel(r.elastic_energy, static_cast<double>(c.energy)), 1e-12);
}

TEST(ReferenceAnalytic, OneStoryUnderSampledHarmonicGroundAcceleration) {
  SceneParams p;
  const Sdof s = one_story(&p);
  const double rate = 50.0;
  std::vector<double> a;
  for (int k = 0; k <= 500; ++k) a.push_back(3.0 * std::sin(2 * M_PI * 1.1 * k / rate));
  const Closed c = closed_form(s, a, rate);
  const Result r = integrate(p, a, rate, Method::kReference, {});
  std::printf("[ measured ] peak rel err %.1e, E_e rel err %.1e\n", rel(r.peak_top, static_cast<double>(c.peak)),
              rel(r.elastic_energy, static_cast<double>(c.energy)));
  EXPECT_LT(rel(r.peak_top, static_cast<double>(c.peak)), 1e-12);
  EXPECT_LT(rel(r.elastic_energy, static_cast<double>(c.energy)), 1e-12);
}

// ---- Hertz impact on a (practically) fixed wall ----

TEST(ReferenceAnalytic, HertzBounceMatchesContactDurationAndConservesEnergy) {
  SceneParams p;
  p.frame.stories = 1;
  p.frame.mass_kg[0] = 1e20;  // the wall does not move
  p.frame.stiffness_n_per_m[0] = 1.0;
  p.frame.stiffness_damping_s = 0.0;
  p.device.kind = DeviceKind::kVines;
  p.device.mass_kg = 55790.0;
  p.device.vines.law = ContactLaw::kHertz;
  const VinesDesign d = design_vines(p.device.vines, p.device.mass_kg, p.frame.mass_kg[0]);
  const double v = 0.5, d0 = 0.01;
  p.device.vines.start_at_left_wall = false;
  p.device.vines.initial_position_m = -d.gap + d0;
  p.device.vines.initial_velocity_mps = -v;
  const std::vector<double> a(2, 0.0);
  Options o;
  const double t_travel = 2 * d.gap / v;
  o.duration_s = d0 / v + t_travel + 0.1;
  const Result r = integrate(p, a, 1.0 / (2 * o.duration_s), Method::kReference, o);
  ASSERT_EQ(r.contacts, 2);
  // Deepest overlap (5 m v^2 / 4 C)^(2/5); duration 2 I d_max / v with
  // I = integral_0^1 (1 - x^(5/2))^(-1/2) dx = sqrt(pi) Gamma(7/5) / Gamma(9/10).
  const LD dmax = std::pow(5.0L * d.mass * v * v / (4.0L * d.c), 0.4L);
  const LD tc = 2 * std::sqrt(M_PIl) * std::tgamma(1.4L) / std::tgamma(0.9L) * dmax / v;
  EXPECT_LT(rel(r.max_overlap, static_cast<double>(dmax)), 1e-12);
  EXPECT_NEAR(r.contact_start_s[0], d0 / v, 1e-13);
  // Elastic: the particle leaves at v and crosses the box to the other wall.
  const double v_out = 2 * d.gap / (r.contact_start_s[1] - r.contact_start_s[0] - static_cast<double>(tc));
  std::printf("[ measured ] overlap rel err %.1e, rebound speed rel err %.1e\n",
              rel(r.max_overlap, static_cast<double>(dmax)), rel(v_out, v));
  EXPECT_LT(rel(v_out, v), 1e-11);
}

// ---- the tuned DOP853 (the `dop853` baseline of `vines bench`) ----

// Its right-hand side (TunedOde: the frame's three diagonals, fixed sizes)
// equals SceneOde<double>::rhs on random states, in every mode the scene has.
template <int F, int D>
void expect_same_rhs(const SceneParams& p, const char* what) {
  const OdeSpec spec = make_spec(p);
  const TunedOde<F, D> tuned(spec);
  const SceneOde<double> ode(spec);
  const int n = ode.size(), nf = ode.floors(), f = spec.floor;
  std::vector<Mode> modes = {Mode::kFree};
  if (ode.has_particle())
    modes = {Mode::kFree, Mode::kContactLeft, Mode::kContactRight, Mode::kStuckLeft, Mode::kStuckRight};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> y(static_cast<std::size_t>(n)), a(y), b(y);
  for (Mode mode : modes)
    for (int trial = 0; trial < 200; ++trial) {
      for (int i = 0; i < n; ++i) y[static_cast<std::size_t>(i)] = (i < n / 2 ? 0.3 : 1.0) * u(rng);
      // The particle across the whole box and a little into either wall.
      if (n / 2 > nf) y[static_cast<std::size_t>(nf)] = y[static_cast<std::size_t>(f)] + spec.wall_left +
                                                          (0.5 + 0.52 * u(rng)) * (spec.wall_right - spec.wall_left);
      const double ag = 3.0 * u(rng);
      tuned.rhs(ag, y.data(), a.data(), mode);
      ode.rhs(ag, y.data(), b.data(), mode);
      double scale = 0.0;
      for (double v : b) scale = std::max(scale, std::fabs(v));
      for (int i = 0; i < n; ++i)
        ASSERT_NEAR(a[static_cast<std::size_t>(i)], b[static_cast<std::size_t>(i)], 1e-13 * scale)
            << what << ", mode " << static_cast<int>(mode) << ", component " << i;
    }
}

TEST(ReferenceDop853, TunedRightHandSideEqualsSceneOde) {
  for (ContactLaw law : {ContactLaw::kKuwabara, ContactLaw::kHertz, ContactLaw::kTsuji, ContactLaw::kRestitution})
    expect_same_rhs<10, 1>(test::paper_scene(DeviceKind::kVines, law), law_name(law));
  expect_same_rhs<10, 1>(test::paper_scene(DeviceKind::kTmd), "tmd");
  expect_same_rhs<10, 0>(test::paper_scene(DeviceKind::kNone), "bare");
  // Any other size at run time; a damping rule whose C is not tridiagonal
  // (SceneOde's own banded product then).
  SceneParams p = test::paper_scene(DeviceKind::kVines);
  p.frame.stories = 3;
  expect_same_rhs<0, 0>(p, "3 stories");
  p = test::paper_scene(DeviceKind::kVines);
  p.frame.damping = DampingRule::kModal;
  expect_same_rhs<10, 1>(p, "modal damping");
}

// A shipped El Centro scene on the record's own points, as `vines bench`
// feeds its baselines.
Result on_record(const std::string& name, Method m, double rtol) {
  host::Scene scene = host::load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/" + name + ".toml");
  scene.params.loop.sensor_rate_hz = 1.0 / host::load_excitation(scene, "").record.dt_s;
  const host::Excitation ex = host::load_excitation(scene, "");
  Options o;
  o.rtol = rtol;
  return integrate(scene.params, ex.samples, ex.rate_hz, m, o);
}

// At rtol 1e-12 it is the long-double reference (data/reference, rtol
// 1e-15): the peak and its time (at a zero of the top-floor velocity on the
// dense output), E_e, the contacts and when they start (over the first 10 s:
// later the chaos amplifies any difference, the reference driver's too), the
// deepest overlap (at a zero of the overlap rate). Measured: peaks 2.3e-12
// (Kuwabara), 4.9e-12 (Hertz), 7.2e-12 (Tsuji); E_e 6.9e-9, 3.4e-8, 1.9e-7
// (the late contacts are chaotic); starts 2e-11 to 3.7e-10 s; deepest
// overlaps 1e-11 to 1.1e-10; bare frame and TMD 6e-15.
TEST(ReferenceDop853, TunedAgreesWithTheStoredReferences) {
  struct Case {
    const char* scene;
    double peak_tol, energy_tol;
  };
  for (const Case& c : {Case{"elcentro_vines", 1e-10, 2e-6}, Case{"elcentro_vines_hertz", 1e-10, 2e-6},
                        Case{"elcentro_vines_tsuji", 1e-10, 2e-6}, Case{"elcentro_bare", 1e-12, 1e-12},
                        Case{"elcentro_tmd", 1e-12, 1e-12}}) {
    const nlohmann::json ref = test::reference(c.scene);
    const Result r = on_record(c.scene, Method::kDop853, 1e-12);
    const double peak = ref["peak_top_displacement_m"].get<double>(), energy = ref["elastic_energy_Js"].get<double>();
    const std::vector<double> starts = ref["contact_starts_s"].get<std::vector<double>>();
    double early = 0;  // contact starts over the first 10 s
    for (std::size_t i = 0; i < std::min(starts.size(), r.contact_start_s.size()) && starts[i] < 10.0; ++i)
      early = std::max(early, std::fabs(r.contact_start_s[i] - starts[i]));
    const double overlap = ref["max_overlap_m"].get<double>();
    const double doverlap = overlap > 0.0 ? rel(r.max_overlap, overlap) : r.max_overlap;
    std::printf("[ measured ] %s: peak %.1e (at %.1e s), E_e %.1e, contacts %d (%zu), starts %.1e s, deepest "
                "overlap %.1e, %lld steps\n",
                c.scene, rel(r.peak_top, peak), std::fabs(r.t_peak_top - ref["t_peak_top_s"].get<double>()),
                rel(r.elastic_energy, energy), r.contacts, starts.size(), early, doverlap, r.steps);
    EXPECT_LT(rel(r.peak_top, peak), c.peak_tol) << c.scene;
    EXPECT_NEAR(r.t_peak_top, ref["t_peak_top_s"].get<double>(), 1e-8) << c.scene;
    EXPECT_LT(rel(r.elastic_energy, energy), c.energy_tol) << c.scene;
    EXPECT_EQ(r.contacts, ref["contacts"].get<int>()) << c.scene;
    EXPECT_LT(early, 5e-9) << c.scene;
    EXPECT_LT(doverlap, 1e-9) << c.scene;
  }
}

// Its errors against the stored reference fall with its tolerance (by about
// 100 from one line to the next, measured), as its steps grow; at each
// tolerance it is as accurate as the reference driver in double.
TEST(ReferenceDop853, TunedErrorFallsWithTheTolerance) {
  const nlohmann::json ref = test::reference("elcentro_vines");
  const double peak = ref["peak_top_displacement_m"].get<double>(), energy = ref["elastic_energy_Js"].get<double>();
  double last_peak = 1, last_energy = 1;
  long long last_steps = 0;
  for (double rtol : {1e-6, 1e-8, 1e-10, 1e-12}) {
    const Result r = on_record("elcentro_vines", Method::kDop853, rtol);
    const Result d = on_record("elcentro_vines", Method::kDop853Driver, rtol);
    std::printf("[ measured ] rtol %.0e: peak %.2e (driver %.2e), E_e %.2e (driver %.2e), %lld steps, %lld "
                "rejected, %lld evaluations (driver %lld), %.2f ms (driver %.2f)\n",
                rtol, rel(r.peak_top, peak), rel(d.peak_top, peak), rel(r.elastic_energy, energy),
                rel(d.elastic_energy, energy), r.steps, r.rejected, r.rhs_evals, d.rhs_evals, 1e3 * r.wall_s,
                1e3 * d.wall_s);
    EXPECT_LT(rel(r.peak_top, peak), 0.1 * last_peak) << rtol;
    EXPECT_LT(rel(r.elastic_energy, energy), 0.1 * last_energy) << rtol;
    EXPECT_GT(r.steps, last_steps) << rtol;
    EXPECT_LT(rel(r.peak_top, peak), 5 * rel(d.peak_top, peak) + 1e-13) << rtol;
    EXPECT_LT(r.rhs_evals, d.rhs_evals) << rtol;
    EXPECT_EQ(r.contacts, ref["contacts"].get<int>()) << rtol;
    last_peak = rel(r.peak_top, peak), last_energy = rel(r.elastic_energy, energy), last_steps = r.steps;
  }
}

// ---- bad input ----

TEST(ReferenceInput, BadInputIsAClearException) {
  SceneParams p = test::paper_scene(DeviceKind::kVines);
  const std::vector<double> a = {0.0, 1.0, 0.0};
  auto message = [&](const SceneParams& sp, const std::vector<double>& s, double rate, Method m, Options o) {
    try {
      integrate(sp, s, rate, m, o);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  SceneParams bad = p;
  bad.device.vines.beta = 0.5;
  EXPECT_NE(message(bad, a, 50, Method::kReference, {}).find("vines.beta"), std::string::npos);
  bad = p;
  bad.frame.mass_kg[3] = -1;
  EXPECT_NE(message(bad, a, 50, Method::kCvodeBdf, {}).find("frame.masses[3]"), std::string::npos);
  EXPECT_NE(message(p, {}, 50, Method::kReference, {}).find("need at least 2"), std::string::npos);
  EXPECT_NE(message(p, {0.0, NAN}, 50, Method::kCvodeAdams, {}).find("sample 1"), std::string::npos);
  EXPECT_NE(message(p, a, 0, Method::kReference, {}).find("rate"), std::string::npos);
  Options o;
  o.rtol = 1e-20;
  EXPECT_NE(message(p, a, 50, Method::kReference, o).find("rtol"), std::string::npos);
  o.rtol = 1e-14;  // fine for the long-double reference, below what double can honour
  EXPECT_EQ(message(p, a, 50, Method::kReference, o), "no exception");
  EXPECT_NE(message(p, a, 50, Method::kDop853, o).find("rtol 1e-14 out of range for DOP853 (double)"),
            std::string::npos);
  o.rtol = 0;
  o.duration_s = -1;
  EXPECT_NE(message(p, a, 50, Method::kReference, o).find("duration"), std::string::npos);
}

#ifndef VINES_HAVE_CVODE
// A build without SUNDIALS: asking for CVODE is refused, saying how to get it
// (and the reference and the DOP853 baseline still integrate).
TEST(Reference, WithoutCvodeSaysHowToGetIt) {
  const SceneParams p = test::paper_scene(DeviceKind::kVines);
  const std::vector<double> a = {0.0, 1.0, 0.0};
  for (Method m : {Method::kCvodeAdams, Method::kCvodeBdf}) {
    try {
      integrate(p, a, 50, m, {});
      ADD_FAILURE() << method_name(m) << " ran in a build without CVODE";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("no CVODE"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("libsundials-dev"), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(integrate(p, a, 50, Method::kReference, {}).steps, 0);
  EXPECT_GT(integrate(p, a, 50, Method::kDop853, {}).steps, 0);
  EXPECT_GT(integrate(p, a, 50, Method::kDop853Driver, {}).steps, 0);
}
#endif

}  // namespace
