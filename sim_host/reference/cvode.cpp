// The CVODE baseline: the same ODE in double, Adams (fixed-point iteration,
// order at most 5) or BDF (Newton, dense direct solver, difference-quotient
// Jacobian), events as CVODE roots, the mode switched at a root and CVODE
// re-initialised there, every sample time a stop time (a_g has a kink there).
// Measured on El Centro (VI NES, rtol 1e-6 to 1e-10, docs/speed.md): the stop
// times pay (without them the kinks cost more steps and error-test failures:
// 71 against 68 ms at 1e-6, 276 against 211 ms at 1e-10); Adams' order held
// to 5 (its history crosses a kink every sample) takes 194 against 226 ms at
// 1e-10 over 9 scaled runs with a smaller error, the same at 1e-6; fixed-point
// acceleration, more or fewer iterations, a looser convergence test, a
// re-initialisation at every sample or one-step returns do not pay.
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_host/reference/integrators.hpp"
#include "sim_host/reference/ode.hpp"

namespace vines::host::reference {
namespace {

// Roots in every mode: 0 the top-floor velocity (peaks). Free flight: 1, 2
// the overlap with the left, right wall beyond the start depth. Contact: 1
// the overlap back to zero, 2 its rate (deepest overlap). Riding: 1 the pull.
class CvodeRun {
 public:
  CvodeRun(const OdeSpec& spec, const Ground& g, double rtol, bool bdf) : ode_(spec), g_(g), bdf_(bdf) {
    const sunindextype n = ode_.size();
    check(SUNContext_Create(nullptr, &ctx_), "SUNContext_Create");
    y_ = N_VNew_Serial(n, ctx_);
    atol_ = N_VNew_Serial(n, ctx_);
    const std::vector<double> sc = ode_.scales();
    for (sunindextype i = 0; i < n; ++i) NV_Ith_S(atol_, i) = rtol * sc[static_cast<std::size_t>(i)];
    ode_.initial_state(NV_DATA_S(y_));
    mem_ = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, ctx_);
    if (!mem_) throw std::runtime_error("cvode: CVodeCreate failed");
    check(CVodeSetErrHandlerFn(mem_, &CvodeRun::on_error, this), "CVodeSetErrHandlerFn");
    check(CVodeInit(mem_, &CvodeRun::rhs, 0.0, y_), "CVodeInit");
    check(CVodeSetUserData(mem_, this), "CVodeSetUserData");
    check(CVodeSVtolerances(mem_, rtol, atol_), "CVodeSVtolerances");
    check(CVodeSetMaxNumSteps(mem_, 1000000), "CVodeSetMaxNumSteps");
    check(CVodeSetNoInactiveRootWarn(mem_), "CVodeSetNoInactiveRootWarn");
    if (bdf) {
      A_ = SUNDenseMatrix(n, n, ctx_);
      ls_ = SUNLinSol_Dense(y_, A_, ctx_);
      check(CVodeSetLinearSolver(mem_, ls_, A_), "CVodeSetLinearSolver");
    } else {
      nls_ = SUNNonlinSol_FixedPoint(y_, 0, ctx_);
      check(CVodeSetNonlinearSolver(mem_, nls_), "CVodeSetNonlinearSolver");
      check(CVodeSetMaxOrd(mem_, 5), "CVodeSetMaxOrd");
    }
    set_roots();
  }
  CvodeRun(const CvodeRun&) = delete;
  CvodeRun& operator=(const CvodeRun&) = delete;
  ~CvodeRun() {
    CVodeFree(&mem_);
    if (ls_) SUNLinSolFree(ls_);
    if (A_) SUNMatDestroy(A_);
    if (nls_) SUNNonlinSolFree(nls_);
    N_VDestroy(y_);
    N_VDestroy(atol_);
    SUNContext_Free(&ctx_);
  }

  Result run() {
    const std::vector<double>& a = *g_.samples;
    for (k_ = 0; k_ < g_.intervals; ++k_) {
      t0_ = k_ / g_.rate_hz;
      const double t1 = k_ + 1 == g_.intervals ? g_.t_end : (k_ + 1) / g_.rate_hz;
      a0_ = a[static_cast<std::size_t>(k_)];
      slope_ = (a[static_cast<std::size_t>(k_) + 1] - a0_) * g_.rate_hz;
      check(CVodeSetStopTime(mem_, t1), "CVodeSetStopTime");
      double t = t0_;
      while (t < t1) {
        const int flag = CVode(mem_, t1, y_, &t, CV_NORMAL);
        if (flag < 0) throw std::runtime_error("cvode: CVode failed at t = " + std::to_string(t) + " s: " + error_);
        const double* y = NV_DATA_S(y_);
        tally_.peak(std::fabs(ode_.top_x(y)), t);
        if (flag == CV_ROOT_RETURN) on_roots(t);
      }
    }
    collect();
    tally_.r.elastic_energy = NV_Ith_S(y_, ode_.energy_index());
    return tally_.r;
  }

 private:
  static void check(int flag, const char* what) {
    if (flag < 0) throw std::runtime_error(std::string("cvode: ") + what + " failed (" + std::to_string(flag) + ")");
  }
  static void on_error(int, const char*, const char* function, char* msg, void* self) {
    static_cast<CvodeRun*>(self)->error_ = std::string(function) + ": " + msg;
  }
  static int rhs(realtype t, N_Vector y, N_Vector dy, void* self) {
    CvodeRun& r = *static_cast<CvodeRun*>(self);
    r.ode_.rhs(r.a0_ + r.slope_ * (t - r.t0_), NV_DATA_S(y), NV_DATA_S(dy), r.mode_);
    return 0;
  }
  int side() const { return mode_ == Mode::kContactLeft || mode_ == Mode::kStuckLeft ? -1 : 1; }
  static int roots(realtype, N_Vector yv, realtype* g, void* self) {
    const CvodeRun& r = *static_cast<CvodeRun*>(self);
    const SceneOde<double>& o = r.ode_;
    const double* y = NV_DATA_S(yv);
    g[0] = o.top_v(y);
    if (!o.has_particle()) return 0;
    const int s = r.side();
    switch (r.mode_) {
      case Mode::kFree:
        g[1] = o.overlap(y, -1) - o.start_depth();
        g[2] = o.overlap(y, 1) - o.start_depth();
        break;
      case Mode::kContactLeft:
      case Mode::kContactRight:
        g[1] = -o.overlap(y, s);
        g[2] = o.overlap_rate(y, s);
        break;
      default:
        g[1] = s < 0 ? -o.holding_force(y) : o.holding_force(y);
        break;
    }
    return 0;
  }
  void set_roots() {
    int dir[3] = {0, 1, 1};
    int n = 1;
    if (ode_.has_particle()) n = riding(mode_) ? 2 : 3;
    if (in_contact(mode_)) dir[2] = -1;
    check(CVodeRootInit(mem_, n, &CvodeRun::roots), "CVodeRootInit");
    check(CVodeSetRootDirection(mem_, dir), "CVodeSetRootDirection");
  }
  // Adds CVODE's counters (a re-initialisation resets them).
  void collect() {
    long s = 0, fe = 0, fl = 0, etf = 0;
    CVodeGetNumSteps(mem_, &s);
    CVodeGetNumRhsEvals(mem_, &fe);
    CVodeGetNumErrTestFails(mem_, &etf);
    if (bdf_) CVodeGetNumLinRhsEvals(mem_, &fl);
    tally_.r.steps += s;
    tally_.r.rhs_evals += fe + fl;
    tally_.r.rejected += etf;
  }

  void on_roots(double t) {
    int found[3] = {0, 0, 0};
    check(CVodeGetRootInfo(mem_, found), "CVodeGetRootInfo");
    double* y = NV_DATA_S(y_);
    ++tally_.r.events;
    if (in_contact(mode_) && found[2]) tally_.overlap(ode_.overlap(y, side()));
    if (!ode_.has_particle()) return;
    int s = found[1] ? side() : 0;  // the wall of a mode event
    if (mode_ == Mode::kFree) s = found[1] ? -1 : found[2] ? 1 : 0;
    if (!s) return;
    const Mode before = mode_;
    if (!take_event(mode_, s, ode_, y, tally_, t)) return;
    // New smooth piece (or a velocity jump): restart CVODE here.
    collect();
    check(CVodeReInit(mem_, t, y_), "CVodeReInit");
    if (mode_ != before) set_roots();
  }

  SceneOde<double> ode_;
  Ground g_;
  bool bdf_;
  SUNContext ctx_ = nullptr;
  void* mem_ = nullptr;
  N_Vector y_ = nullptr, atol_ = nullptr;
  SUNMatrix A_ = nullptr;
  SUNLinearSolver ls_ = nullptr;
  SUNNonlinearSolver nls_ = nullptr;
  Mode mode_ = Mode::kFree;
  int k_ = 0;
  double t0_ = 0, a0_ = 0, slope_ = 0;
  std::string error_;
  Tally tally_;
};

}  // namespace

Result integrate_cvode(const OdeSpec& spec, const Ground& g, double rtol, bool bdf) {
  return CvodeRun(spec, g, rtol, bdf).run();
}

}  // namespace vines::host::reference
