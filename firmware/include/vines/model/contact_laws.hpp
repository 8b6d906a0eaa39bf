// The contact laws of the VI NES in one registry. Each law is one struct:
//   kTag        its code (ContactLaw, params.hpp): the byte model images and
//               configure messages carry; equal to its line in the table
//   kName       what scene files (vines.law), outputs and messages call it
//   kImpulsive  true: an instantaneous impact (Newton's law), no force over
//               a contact; its kernel then only carries C (scales, energy)
//   Kernel<S>   its coefficients and force in the loop's scalar
//               (contact.hpp: force(d, dd), regular(q, dd), coefficients)
//   kernel<S>(d)  that kernel from a design
//   check(p)    its own parameter checks (validate.hpp calls it)
//   design(p, d)  its design step: its constants, once, in double
//   keep(d, p)  makes the parameters p rebuild the design d without its
//               calibration (the runs of a study share one: Kuwabara's tau)
//   kBalanceTol the energy-balance residual (relative) a run of the law is
//               held to (vines stress; measured, docs/speed.md)
// ContactLaws, the table below, lists them, one line a law. Everything that
// enumerates laws reads it: the scene choices and names (law_name,
// each_law), validation, the model's kernel type (LawOf), the model image's
// law fields, and the host's engine instances (sim_host/CMakeLists.txt reads
// the table's lines). Adding a law: docs/model.md section 4.6.
#pragma once

#include <cmath>

#include "vines/model/bounce.hpp"
#include "vines/model/contact.hpp"
#include "vines/model/param_error.hpp"
#include "vines/model/params.hpp"

namespace vines {

// ---- what a VI NES design holds: the sphere, the box and the law's constants
struct VinesDesign {
  double mass = 0, radius = 0, box_length = 0, gap = 0;  // gap: free travel of the centre
  double c = 0;       // Hertz prefactor
  double m_star = 0;  // particle/floor reduced mass (Tsuji, restitution)
  double eps = 1, tau = 0, v_ref = 0;
  double g = 0;       // rate-term prefactor of the law (Tsuji or Kuwabara)
  bool ok = true;     // false: tau could not be calibrated
};

namespace laws {

// The restitution target eps, for the laws that dissipate.
inline ParamError check_eps(const VinesParams& v) {
  if (!(std::isfinite(v.eps) && v.eps > 0.0 && v.eps <= 1.0)) return {"vines.eps", "must be in (0, 1]"};
  return {};
}

// Hertz: elastic, F = C d^{3/2}; nothing is lost (eps is 1 whatever is given).
struct Hertz {
  static constexpr ContactLaw kTag = ContactLaw::kHertz;
  static constexpr const char* kName = "hertz";
  static constexpr bool kImpulsive = false;
  template <typename S>
  using Kernel = contact::Hertz<S>;
  template <typename S>
  static Kernel<S> kernel(const VinesDesign& d) { return {static_cast<S>(d.c)}; }
  static ParamError check(const VinesParams&) { return {}; }
  static void design(const VinesParams&, VinesDesign* d) { d->eps = 1.0; }
  static void keep(const VinesDesign&, VinesParams*) {}
  static constexpr double kBalanceTol = 1e-5;  // elastic: chatters most
};

// Tsuji: g = D(eps) sqrt(C m*), m* the particle/floor reduced mass.
struct Tsuji {
  static constexpr ContactLaw kTag = ContactLaw::kTsuji;
  static constexpr const char* kName = "tsuji";
  static constexpr bool kImpulsive = false;
  template <typename S>
  using Kernel = contact::Tsuji<S>;
  template <typename S>
  static Kernel<S> kernel(const VinesDesign& d) { return {static_cast<S>(d.c), static_cast<S>(d.g)}; }
  static ParamError check(const VinesParams& v) { return check_eps(v); }
  static void design(const VinesParams& p, VinesDesign* d) {
    d->eps = p.eps;
    d->g = contact::tsuji_d(d->eps) * std::sqrt(d->c * d->m_star);
  }
  static void keep(const VinesDesign&, VinesParams*) {}
  static constexpr double kBalanceTol = 1e-7;
};

// Kuwabara-Kono: g = 1.5 C tau, tau given or calibrated so that the particle
// alone rebounds from a fixed rigid wall at v_ref with restitution eps.
struct Kuwabara {
  static constexpr ContactLaw kTag = ContactLaw::kKuwabara;
  static constexpr const char* kName = "kuwabara";
  static constexpr bool kImpulsive = false;
  template <typename S>
  using Kernel = contact::Kuwabara<S>;
  template <typename S>
  static Kernel<S> kernel(const VinesDesign& d) { return {static_cast<S>(d.c), static_cast<S>(d.g)}; }
  static ParamError check(const VinesParams& v) {
    const ParamError e = check_eps(v);
    if (!e.ok()) return e;
    if (v.tau_s != 0.0) {
      // A steel sphere's is under a millisecond; a long one holds the sphere
      // on the wall, each step at its most substeps (1e6 s: a run of hours).
      if (!(std::isfinite(v.tau_s) && v.tau_s > 0.0 && v.tau_s <= 1.0)) return {"vines.tau_s", "must be in (0, 1] s"};
    } else if (!(std::isfinite(v.v_ref_mps) && v.v_ref_mps >= 1e-4 && v.v_ref_mps <= 1e3)) {
      // Below 0.1 mm/s no impact is measured, and the calibration's contact
      // time grows without bound (1e-300 m/s: 15 s of work, tau 3e52 s).
      return {"vines.v_ref_mps", "must be in [1e-4, 1000] m/s"};
    }
    return {};
  }
  static void design(const VinesParams& p, VinesDesign* d) {
    d->eps = p.eps;
    d->tau = p.tau_s > 0.0 ? p.tau_s : calibrate_kuwabara_tau(d->c, d->mass, d->eps, d->v_ref);
    d->ok = d->tau >= 0.0;
    d->g = 1.5 * d->c * d->tau;
  }
  static void keep(const VinesDesign& d, VinesParams* p) {
    if (p->tau_s == 0.0 && d.tau > 0.0) p->tau_s = d.tau;
  }
  static constexpr double kBalanceTol = 1e-7;
};

// Restitution: Newton's law with eps between the particle and the floor mass
// (Eq. 4), applied at the instant of impact (substep.hpp).
struct Restitution {
  static constexpr ContactLaw kTag = ContactLaw::kRestitution;
  static constexpr const char* kName = "restitution";
  static constexpr bool kImpulsive = true;
  template <typename S>
  using Kernel = contact::Hertz<S>;
  template <typename S>
  static Kernel<S> kernel(const VinesDesign& d) { return {static_cast<S>(d.c)}; }
  static ParamError check(const VinesParams& v) { return check_eps(v); }
  static void design(const VinesParams& p, VinesDesign* d) { d->eps = p.eps; }
  static void keep(const VinesDesign&, VinesParams*) {}
  static constexpr double kBalanceTol = 1e-8;
};

}  // namespace laws

template <typename... Ls>
struct LawTable {
  static constexpr int kCount = sizeof...(Ls);
};

// ---- the table: one line a law, in the order of their codes. CMake reads
// these lines (`    laws::Name,`): keep one law a line in this form.
using ContactLaws = LawTable<
    laws::Hertz,
    laws::Tsuji,
    laws::Kuwabara,
    laws::Restitution>;

inline constexpr int kContactLawCount = ContactLaws::kCount;

namespace detail {

template <typename... Ls>
constexpr bool codes_in_order(LawTable<Ls...>) {
  int i = 0;
  return ((static_cast<int>(Ls::kTag) == i++) && ...);
}

template <typename... Ls, typename F>
constexpr bool with_law_in(LawTable<Ls...>, ContactLaw law, F& f) {
  return ((law == Ls::kTag ? (f(Ls{}), true) : false) || ...);
}

template <typename... Ls, typename F>
constexpr void each_law_in(LawTable<Ls...>, F& f) {
  (f(Ls{}), ...);
}

// The I-th law of a list.
template <int I, typename L, typename... Ls>
struct LawAt {
  using type = typename LawAt<I - 1, Ls...>::type;
};
template <typename L, typename... Ls>
struct LawAt<0, L, Ls...> {
  using type = L;
};
template <int I, typename... Ls>
typename LawAt<I, Ls...>::type law_at(LawTable<Ls...>);

}  // namespace detail

static_assert(detail::codes_in_order(ContactLaws{}),
              "ContactLaws: a law's kTag must be its line in the table (0, 1, ...)");

// The struct of the law with code L (the compiled device's law).
template <ContactLaw L>
using LawOf = decltype(detail::law_at<static_cast<int>(L)>(ContactLaws{}));

// Calls f(Law{}) with the struct of the law tagged `law`; false (f not
// called) for a code no law has.
template <typename F>
constexpr bool with_law(ContactLaw law, F&& f) {
  return detail::with_law_in(ContactLaws{}, law, f);
}

// Calls f(Law{}) for every law, in the table's order.
template <typename F>
constexpr void each_law(F&& f) {
  detail::each_law_in(ContactLaws{}, f);
}

// "kuwabara"; nullptr for a code no law has.
constexpr const char* law_name(ContactLaw law) {
  const char* name = nullptr;
  with_law(law, [&](auto l) { name = decltype(l)::kName; });
  return name;
}

// The parameters p rebuild the design d without its law's calibration.
inline void law_keep(const VinesDesign& d, VinesParams* p) {
  with_law(p->law, [&](auto l) { decltype(l)::keep(d, p); });
}

// The law is an instantaneous impact (false for a code no law has).
constexpr bool law_impulsive(ContactLaw law) {
  bool impulsive = false;
  with_law(law, [&](auto l) { impulsive = decltype(l)::kImpulsive; });
  return impulsive;
}

}  // namespace vines
