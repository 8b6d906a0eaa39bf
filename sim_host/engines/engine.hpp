// Host access to one compiled instance of the firmware core. The core is a set
// of templates over (scalar, story count, device); an Engine hides which one a
// scene needs behind a small virtual interface so that host programs can pick
// it at run time. Each instance lives in its own translation unit, compiled
// with the firmware's flags (no exceptions, no RTTI).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "sim_host/scene/scalar.hpp"
#include "vines/model/data.hpp"
#include "vines/model/params.hpp"
#include "vines/model/validate.hpp"

namespace vines::host {

using FloorArray = std::array<double, kMaxStories>;

// The outputs of one step, in double.
struct Snapshot {
  double t = 0, ag = 0;
  FloorArray x{}, v{}, acc{}, drift{};  // relative disp./vel., absolute acc., story drift
  double elastic_energy = 0;            // E_e so far [J s]
  // VI NES
  double particle_x = 0, particle_v = 0;  // centre relative to ground, from the box centre at rest
  double wall_left = 0, wall_right = 0;   // where the particle centre touches each wall
  double contact_force = 0;               // on the particle, positive to the right
  int mode = 0;                           // vines::Mode
  // TMD
  double tmd_x = 0, tmd_v = 0;
};

// Everything a run summary reports that the model knows.
struct ModelInfo {
  int stories = 0;
  FloorArray frequency_hz{}, zeta{}, gamma{}, m_eff{};
  std::array<FloorArray, kMaxStories> mode_shapes{};  // mode_shapes[j][i]: floor i of mode j
  double total_mass = 0;
  double sensor_period = 0;
  int device_floor = 0;  // 1-based
  TmdDesign tmd;
  VinesDesign vines;
};

struct RunTotals {
  FloorArray peak_x{}, peak_drift{};
  double peak_top = 0, t_peak_top = 0;
  double peak_top_velocity = 0;
  double elastic_energy = 0, strain_increments = 0;
  double max_overlap = 0;
  Ledger ledger;
  Counters count;
  std::int64_t fixed_saturations = 0;  // fixed-point operations saturated (loop.scalar = "fixed")
};

// What the loop holds after a step, cheap to read every step (no outputs
// computed): counters, ledger, and the VI NES particle against the walls.
struct Probe {
  Counters count;
  Ledger ledger;
  double peak_top = 0;  // running peak of the top floor [m]
  int mode = 0;         // vines::Mode (VI NES)
  double overlap = 0;   // how far the particle is past the nearer wall now [m] (< 0: still short of it)
};

// A physical state to put the loop in (Engine::set_physical), in double, in
// Snapshot's conventions. NaN leaves a quantity as it is: the default, so
// set only what is known. x and v are all or nothing (their first `stories`
// entries); the particle's and the TMD's fields apply to that device only
// (NaN for any other).
struct PhysicalState {
  static constexpr double kKeep = std::numeric_limits<double>::quiet_NaN();
  static constexpr FloorArray keep_floors() {
    FloorArray a{};
    for (double& e : a) e = kKeep;
    return a;
  }
  FloorArray x = keep_floors(), v = keep_floors();  // floors relative to ground [m, m/s]
  double particle_x = kKeep, particle_v = kKeep;    // VI NES centre relative to ground, from the box centre at rest
  double tmd_x = kKeep, tmd_v = kKeep;              // TMD relative to ground
};

class Engine {
 public:
  virtual ~Engine() = default;
  // Builds the model; the parameters must fit this engine (see make_engine).
  virtual ParamError build(const SceneParams& p) = 0;
  // Gives the built model the initial conditions of p (vines.initial_*,
  // tmd.initial_*; vines::set_initial_conditions): the model is then, bit
  // for bit, the one build(p) makes when p differs from the built parameters
  // in nothing else. Call init() after it.
  virtual ParamError set_initial_conditions(const SceneParams& p) = 0;
  // The model's image (vines/image/model_image.hpp), after build() or load_image().
  virtual std::vector<std::uint8_t> model_image() const = 0;
  // Loads a model image in place of building: empty on success, after which
  // init/step/run work as after build(); else why it was refused (the model
  // held before is kept). An image carries no modal report: info() then has
  // stories, sensor period, device floor and design, but zero frequencies,
  // damping ratios, participation, effective masses, mode shapes and mass.
  virtual std::string load_image(const std::uint8_t* p, std::size_t n) = 0;
  // What the model knows (partial after load_image, see there).
  virtual ModelInfo info() const = 0;
  virtual void init(double a0) = 0;
  virtual void step(double a1) = 0;
  // step() for each of n samples in turn: one call for a whole record (the
  // loop then runs inside the instance, with no call per sample).
  virtual void run(const double* a, std::size_t n) = 0;
  virtual Snapshot snapshot() const = 0;
  virtual RunTotals totals() const = 0;
  virtual Probe probe() const = 0;

  // The loop's whole state (the data block, bit for bit) as bytes behind a
  // header: magic and version, scalar, story count, device, the block's size
  // and a fingerprint of the model (FNV-1a 64 of model_image()). Loaded into
  // an engine of the same model, stepping goes on bit for bit as it would
  // have here.
  virtual std::vector<std::uint8_t> state() const = 0;
  // Restores a state() of this engine's model: empty on success, else why it
  // was refused (not a loop state, truncated, another scalar, story count,
  // device or model), the current state then untouched.
  virtual std::string load_state(const std::uint8_t* p, std::size_t n) = 0;
  // Puts the loop in a physical state (vines/step/set_state.hpp): the floors
  // solved for the linear state in double, the VI NES particle in free
  // flight, strictly between the walls. The clock, peaks and counters are
  // kept, E_e so far too (it goes on from the new state); with the energy
  // ledger, the change in stored energy counts as energy put in
  // (Ledger::initial). Empty on success, else why it was refused (naming the
  // field; the state is then untouched). Not in fixed point (refused).
  virtual std::string set_physical(const PhysicalState& s) = 0;
  // Takes over `from`'s run at a change of model (damage striking mid-run):
  // `from` an engine of the same scalar, story count and device whose model
  // differs in the frame alone. The loop state becomes from's (clock, sample,
  // peaks, counters, ledger, E_e so far, the VI NES particle and its contact
  // as they are), the linear state the same floors (x, v) and device in this
  // model's coordinates; with the ledger, this model's stored energy less
  // from's counts as energy put in (Ledger::initial). Empty on success, else
  // why not (the state then untouched). Not in fixed point (refused).
  virtual std::string take_over(const Engine& from) = 0;
};

// The engine for a scene's story count, device and law, or nullptr if this
// build does not include it (see VINES_STORY_COUNTS, VINES_STRESS_STORY_COUNTS).
std::unique_ptr<Engine> make_engine(const SceneParams& p, Scalar scalar);

// Story counts with an engine for this scalar and device kind.
std::vector<int> compiled_frames(Scalar scalar, DeviceKind kind);

// The story counts compiled into this build and what each has, for messages.
std::string compiled_story_counts();

// Why make_engine(p, scalar) gave nullptr, and how to reconfigure.
std::string missing_engine(const SceneParams& p, Scalar scalar);

}  // namespace vines::host
