// Payloads of the link's messages (docs/link_protocol.md), their wire layouts
// (one list of fields per message for both directions), and the encoders
// (returning the payload length, 0 if it does not fit) and decoders (false on
// any length or range mismatch: a frame whose CRC passed can still be refused
// here) built on them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>

#include "vines/bytes/wire.hpp"
#include "vines/model/params.hpp"
#include "vines/twin/image.hpp"

namespace vines::link {

// bench -> node ------------------------------------------------------------

inline constexpr std::size_t kChunk = 256;  // configuration bytes per frame

// What a configuration chunk carries: the node's settings (config.hpp), or
// the model image the host built (model_image.hpp), streamed to the plant.
enum class ConfigPart : std::uint8_t { kSettings = 0, kModelImage = 1 };

struct ConfigureChunk {
  ConfigPart part = ConfigPart::kSettings;
  std::uint32_t offset = 0, total = 0;
  std::uint32_t blob_crc = 0;  // CRC-32 of the whole part
  const std::uint8_t* data = nullptr;
  std::uint16_t length = 0;
};

struct Start {
  std::uint32_t k0 = 0;    // index of the first sample (0, or where a restarted node resumes)
  std::uint64_t t_ns = 0;  // bench clock when sent
};

struct Sample {
  std::uint32_t k = 0;     // sample index: due at k / rate on the bench clock
  std::uint64_t t_ns = 0;  // bench clock when sent
  double ag = 0;           // ground acceleration [m/s^2]
  double aux = 0;          // twin: measured top-floor acceleration (NaN: none); hybrid: measured force [N]
  double table_x = 0;      // hybrid: measured table displacement [m] (NaN: none); other modes: 0, unused
  std::uint8_t ny = 0;     // twin with an estimator: floor accelerations measured (0: none)...
  double y[twin::kMaxSensors] = {};  // ...at the twin image's sensors, in its order [m/s^2]
};

// node -> bench ------------------------------------------------------------

// Per-step flags in telemetry.
enum StepFlag : std::uint16_t {
  kInterpolated = 1u << 0,  // sample missing, filled by interpolation
  kHeld = 1u << 1,          // sample missing at its deadline, last value held
  kNonFinite = 1u << 2,     // sample NaN/inf, last value held
  kSaturated = 1u << 3,     // sample at the sensor's range, extrapolated
  kDriftAlarm = 1u << 4,    // a story drift beyond its limit (twin)
  kResidualAlarm = 1u << 5, // top-floor acceleration residual beyond its limit (twin)
  kAuxMissing = 1u << 6,    // measured value missing or non-finite: last one used
  kGuard = 1u << 7,         // the core's guards acted (sample held or step rolled back)
  kDamage = 1u << 8,        // twin estimator: damage detected (latched), story in alarm_story
  kDeviceAlarm = 1u << 9,   // twin estimator: the TMD's spring off its design (detuned)
  kImpact = 1u << 10,       // twin estimator: a VI NES impact (its impact gain on): no residual alarm
};

struct Telemetry {
  std::uint32_t rx = 0;  // frames (delimiters) the node has received so far
  std::uint32_t k = 0;   // step: the state is at sample k
  std::uint16_t flags = 0;
  std::uint8_t n = 0;    // stories
  std::uint8_t contact_mode = 0;
  double ag = 0;         // ground acceleration the step used
  double x[kMaxStories] = {};  // floor displacements [m], bottom first
  double acc_top = 0;    // predicted absolute top-floor acceleration [m/s^2]
  double elastic_energy = 0;   // E_e so far [J s]
  // The device's mass, relative to the ground: the VI NES sphere (with its
  // contact force on it) or, in double and float, the TMD's mass [m, m/s, N].
  double particle_x = 0, particle_v = 0, contact_force = 0;
  double dissipated = 0; // energy dissipated in contacts so far [J] (energy ledger on)
  double aux = 0;        // twin: measured - predicted top acceleration; hybrid: command sent [m]
  std::uint64_t drift_alarms = 0;  // bit i: story i+1 beyond its limit
  std::uint32_t step_ticks = 0;    // the model's work for this step, in the node's counter ticks
  double comp[3] = {};             // hybrid, adaptive: the compensator's a0, a1 [s], a2 [s^2]; else 0
  // Twin estimator: one spring's stiffness factor and its sd per step, in
  // turn (est_index: 0..stories-1 the stories, stories the TMD's spring),
  // and the story in alarm (1-based, 0: none).
  std::uint8_t est_index = 0, alarm_story = 0;
  double est_eta = 0, est_sd = 0;
  // Its decision (twin/decision.hpp): est_index's one-story statistic in
  // the leading test and the absolute test's threshold; a second story
  // (1-based, 0: none), the sizes of both; the onset (s, -1: none).
  double est_stat = 0, stat_threshold = 0;
  std::uint8_t second_story = 0;
  double damage_size = 0, second_size = 0, onset_s = -1;
  double change_score = 0;  // the estimator's change score (twin/estimator.hpp)
};

// The node's deadline monitor: every step's model work timed on the node's
// counter and held against a budget (one sensor period unless configured).
struct StepTiming {
  std::uint32_t counter_hz = 0;    // ticks per second of the node's counter
  std::uint32_t budget_ticks = 0;  // a step over this is an overrun
  std::uint32_t overruns = 0;      // steps over the budget since START
  std::uint32_t worst_ticks = 0;   // the longest step since START...
  std::uint32_t worst_k = 0;       // ...and its sample index
  std::uint32_t stack_peak_bytes = 0;  // deepest stack since power-up (0: unknown)
};

enum class NodeState : std::uint8_t { kBooted, kConfigured, kRunning, kStopped };

// Faults the node detects; each is counted and reported as a Fault message.
enum class FaultCode : std::uint8_t {
  kCrc,          // frame with a bad CRC
  kFraming,      // bad COBS, too short, oversize, empty
  kVersion,      // another protocol version
  kType,         // unknown type, or a payload that does not decode
  kSeqGap,       // frames missing (k: first missing seq, count: how many)
  kDuplicate,    // a frame seen already (k: seq)
  kReordered,    // a frame older than the newest one (k: seq)
  kLate,         // sample past its deadline: already filled, dropped (k: sample)
  kHeld,         // deadline passed without the sample: held (k: sample)
  kNonFinite,    // NaN/inf sample: held (k: sample)
  kSaturated,    // sample at the sensor range (k: sample)
  kStall,        // no frame for longer than the stall limit (count: periods)
  kConfig,       // configuration refused
  kProtocol,     // message not valid in this state (e.g. sample before start)
  kCount
};
inline constexpr int kFaultCodes = static_cast<int>(FaultCode::kCount);

struct Status {
  std::uint32_t rx = 0;
  NodeState state = NodeState::kBooted;
  std::uint8_t cold_start = 1;  // 1 until the first START after power-up: state was lost
  std::uint32_t next_k = 0;     // next sample expected
  std::uint32_t steps = 0;      // steps taken since boot
  std::uint32_t faults[kFaultCodes] = {};
  char message[64] = {};        // why a configuration was refused ("" if none)
  StepTiming timing;            // the deadline monitor's counts
};

struct Fault {
  std::uint32_t rx = 0;
  FaultCode code = FaultCode::kCrc;
  std::uint32_t k = 0;
  std::uint32_t count = 1;
};

// Wire layouts ---------------------------------------------------------------
// Each message's fields in wire order, written once for both directions: `io`
// is a Writer (encode, `m` const) or a Reader (decode), whose field() reads or
// writes one value and whose checks (enumeration, count, text, tail) refuse a
// value out of range on either side.

template <class IO, class M>
void layout(IO& io, M& c, ConfigureChunk*) {
  io.enumeration(c.part, ConfigPart::kModelImage);
  io.field(c.offset);
  io.field(c.total);
  io.field(c.blob_crc);
  io.tail(c.data, c.length, kChunk);  // the chunk's bytes: the rest of the payload
}
// A chunk lies inside its part.
inline bool holds(const ConfigureChunk& c) { return static_cast<std::uint64_t>(c.offset) + c.length <= c.total; }

template <class IO, class M>
void layout(IO& io, M& s, Start*) {
  io.field(s.k0);
  io.field(s.t_ns);
}

template <class IO, class M>
void layout(IO& io, M& s, Sample*) {
  io.field(s.k);
  io.field(s.t_ns);
  io.field(s.ag);
  io.field(s.aux);
  io.field(s.table_x);
  io.field(s.ny);
  if (s.ny > twin::kMaxSensors) io.fail();
  for (int i = 0; i < s.ny && i < twin::kMaxSensors; ++i) io.field(s.y[i]);
}

template <class IO, class M>
void layout(IO& io, M& t, Telemetry*) {
  io.field(t.rx);
  io.field(t.k);
  io.field(t.flags);
  io.count(t.n, kMaxStories);  // the stories that follow: 1..kMaxStories
  io.field(t.contact_mode);
  io.field(t.ag);
  for (int i = 0; i < t.n && i < kMaxStories; ++i) io.field(t.x[i]);
  io.field(t.acc_top);
  io.field(t.elastic_energy);
  io.field(t.particle_x);
  io.field(t.particle_v);
  io.field(t.contact_force);
  io.field(t.dissipated);
  io.field(t.aux);
  io.field(t.drift_alarms);
  io.field(t.step_ticks);
  for (auto& c : t.comp) io.field(c);
  io.field(t.est_index);
  io.field(t.alarm_story);
  io.field(t.est_eta);
  io.field(t.est_sd);
  io.field(t.est_stat);
  io.field(t.stat_threshold);
  io.field(t.second_story);
  io.field(t.damage_size);
  io.field(t.second_size);
  io.field(t.onset_s);
  io.field(t.change_score);
}

template <class IO, class M>
void layout(IO& io, M& s, Status*) {
  io.field(s.rx);
  io.enumeration(s.state, NodeState::kStopped);
  io.field(s.cold_start);
  io.field(s.next_k);
  io.field(s.steps);
  io.constant(static_cast<std::uint8_t>(kFaultCodes));  // the fault counts that follow
  for (auto& f : s.faults) io.field(f);
  io.text(s.message);  // length byte, then the characters
  io.field(s.timing.counter_hz);
  io.field(s.timing.budget_ticks);
  io.field(s.timing.overruns);
  io.field(s.timing.worst_ticks);
  io.field(s.timing.worst_k);
  io.field(s.timing.stack_peak_bytes);
}

template <class IO, class M>
void layout(IO& io, M& f, Fault*) {
  io.field(f.rx);
  io.enumeration(f.code, static_cast<FaultCode>(kFaultCodes - 1));
  io.field(f.k);
  io.field(f.count);
}

// Checks a decoded message beyond its fields' own ranges (by default none).
template <class M>
bool holds(const M&) { return true; }

// Encoders / decoders ------------------------------------------------------
// encode: the payload length, 0 if it does not fit or a value is out of
// range. decode: false on any length or range mismatch.

template <class M, class = decltype(layout(std::declval<Writer&>(), std::declval<const M&>(), static_cast<M*>(nullptr)))>
std::size_t encode(const M& m, std::uint8_t* b, std::size_t cap) {
  Writer w(b, cap);
  layout(w, m, static_cast<M*>(nullptr));
  return w.ok() ? w.size() : 0;
}

template <class M, class = decltype(layout(std::declval<Reader&>(), std::declval<M&>(), static_cast<M*>(nullptr)))>
bool decode(const std::uint8_t* p, std::size_t n, M* m) {
  Reader r(p, n);
  layout(r, *m, static_cast<M*>(nullptr));
  return r.done() && holds(*m);
}

inline const char* fault_name(FaultCode c) {
  static const char* const kNames[kFaultCodes] = {"crc",  "framing",   "version",   "type",  "seq_gap",
                                                  "duplicate", "reordered", "late", "held", "non_finite",
                                                  "saturated", "stall", "config", "protocol"};
  const int i = static_cast<int>(c);
  return i >= 0 && i < kFaultCodes ? kNames[i] : "unknown";
}

}  // namespace vines::link
