// Payloads of the link's messages (docs/link_protocol.md), with their
// encoders (returning the payload length, 0 if it does not fit) and decoders
// (false on any length or range mismatch: a frame whose CRC passed can still
// be refused here).
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>

#include "vines/link/wire.hpp"
#include "vines/params.hpp"

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
  double particle_x = 0, particle_v = 0, contact_force = 0;
  double dissipated = 0; // energy dissipated in contacts so far [J] (energy ledger on)
  double aux = 0;        // twin: measured - predicted top acceleration; hybrid: command sent [m]
  std::uint64_t drift_alarms = 0;  // bit i: story i+1 beyond its limit
  std::uint32_t step_ticks = 0;    // the model's work for this step, in the node's counter ticks
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

// Encoders / decoders ------------------------------------------------------

inline std::size_t encode(const ConfigureChunk& c, std::uint8_t* b, std::size_t cap) {
  Writer w(b, cap);
  w.u8(static_cast<std::uint8_t>(c.part));
  w.u32(c.offset);
  w.u32(c.total);
  w.u32(c.blob_crc);
  w.bytes(c.data, c.length);
  return w.ok() ? w.size() : 0;
}
inline bool decode(const std::uint8_t* p, std::size_t n, ConfigureChunk* c) {
  Reader r(p, n);
  const std::uint8_t part = r.u8();
  c->offset = r.u32();
  c->total = r.u32();
  c->blob_crc = r.u32();
  if (!r.ok() || r.remaining() > kChunk || part > static_cast<std::uint8_t>(ConfigPart::kModelImage)) return false;
  c->part = static_cast<ConfigPart>(part);
  c->length = static_cast<std::uint16_t>(r.remaining());
  c->data = r.bytes(c->length);
  return r.done() && static_cast<std::uint64_t>(c->offset) + c->length <= c->total;
}

inline std::size_t encode(const Start& s, std::uint8_t* b, std::size_t cap) {
  Writer w(b, cap);
  w.u32(s.k0);
  w.u64(s.t_ns);
  return w.ok() ? w.size() : 0;
}
inline bool decode(const std::uint8_t* p, std::size_t n, Start* s) {
  Reader r(p, n);
  s->k0 = r.u32();
  s->t_ns = r.u64();
  return r.done();
}

inline std::size_t encode(const Sample& s, std::uint8_t* b, std::size_t cap) {
  Writer w(b, cap);
  w.u32(s.k);
  w.u64(s.t_ns);
  w.f64(s.ag);
  w.f64(s.aux);
  return w.ok() ? w.size() : 0;
}
inline bool decode(const std::uint8_t* p, std::size_t n, Sample* s) {
  Reader r(p, n);
  s->k = r.u32();
  s->t_ns = r.u64();
  s->ag = r.f64();
  s->aux = r.f64();
  return r.done();
}

inline std::size_t encode(const Telemetry& t, std::uint8_t* b, std::size_t cap) {
  Writer w(b, cap);
  w.u32(t.rx);
  w.u32(t.k);
  w.u16(t.flags);
  w.u8(t.n);
  w.u8(t.contact_mode);
  w.f64(t.ag);
  for (int i = 0; i < t.n && i < kMaxStories; ++i) w.f64(t.x[i]);
  for (double v : {t.acc_top, t.elastic_energy, t.particle_x, t.particle_v, t.contact_force, t.dissipated, t.aux})
    w.f64(v);
  w.u64(t.drift_alarms);
  w.u32(t.step_ticks);
  return w.ok() && t.n <= kMaxStories ? w.size() : 0;
}
inline bool decode(const std::uint8_t* p, std::size_t n, Telemetry* t) {
  Reader r(p, n);
  t->rx = r.u32();
  t->k = r.u32();
  t->flags = r.u16();
  t->n = r.u8();
  t->contact_mode = r.u8();
  if (t->n < 1 || t->n > kMaxStories) return false;
  t->ag = r.f64();
  for (int i = 0; i < t->n; ++i) t->x[i] = r.f64();
  for (double* v : {&t->acc_top, &t->elastic_energy, &t->particle_x, &t->particle_v, &t->contact_force,
                    &t->dissipated, &t->aux})
    *v = r.f64();
  t->drift_alarms = r.u64();
  t->step_ticks = r.u32();
  return r.done();
}

inline std::size_t encode(const Status& s, std::uint8_t* b, std::size_t cap) {
  Writer w(b, cap);
  w.u32(s.rx);
  w.u8(static_cast<std::uint8_t>(s.state));
  w.u8(s.cold_start);
  w.u32(s.next_k);
  w.u32(s.steps);
  w.u8(static_cast<std::uint8_t>(kFaultCodes));
  for (std::uint32_t f : s.faults) w.u32(f);
  std::size_t len = 0;
  while (len < sizeof s.message && s.message[len] != '\0') ++len;
  w.u8(static_cast<std::uint8_t>(len));
  w.bytes(reinterpret_cast<const std::uint8_t*>(s.message), len);
  const StepTiming& t = s.timing;
  for (std::uint32_t v : {t.counter_hz, t.budget_ticks, t.overruns, t.worst_ticks, t.worst_k, t.stack_peak_bytes}) w.u32(v);
  return w.ok() ? w.size() : 0;
}
inline bool decode(const std::uint8_t* p, std::size_t n, Status* s) {
  Reader r(p, n);
  s->rx = r.u32();
  const std::uint8_t state = r.u8();
  s->cold_start = r.u8();
  s->next_k = r.u32();
  s->steps = r.u32();
  if (r.u8() != kFaultCodes || state > static_cast<std::uint8_t>(NodeState::kStopped)) return false;
  s->state = static_cast<NodeState>(state);
  for (std::uint32_t& f : s->faults) f = r.u32();
  const std::uint8_t len = r.u8();
  if (len >= sizeof s->message) return false;
  const std::uint8_t* m = r.bytes(len);
  StepTiming& t = s->timing;
  for (std::uint32_t* v : {&t.counter_hz, &t.budget_ticks, &t.overruns, &t.worst_ticks, &t.worst_k, &t.stack_peak_bytes})
    *v = r.u32();
  if (!r.done()) return false;
  for (std::size_t i = 0; i < sizeof s->message; ++i) s->message[i] = i < len ? static_cast<char>(m[i]) : '\0';
  return true;
}

inline std::size_t encode(const Fault& f, std::uint8_t* b, std::size_t cap) {
  Writer w(b, cap);
  w.u32(f.rx);
  w.u8(static_cast<std::uint8_t>(f.code));
  w.u32(f.k);
  w.u32(f.count);
  return w.ok() ? w.size() : 0;
}
inline bool decode(const std::uint8_t* p, std::size_t n, Fault* f) {
  Reader r(p, n);
  f->rx = r.u32();
  const std::uint8_t code = r.u8();
  f->k = r.u32();
  f->count = r.u32();
  if (code >= kFaultCodes) return false;
  f->code = static_cast<FaultCode>(code);
  return r.done();
}

inline const char* fault_name(FaultCode c) {
  static const char* const kNames[kFaultCodes] = {"crc",  "framing",   "version",   "type",  "seq_gap",
                                                  "duplicate", "reordered", "late", "held", "non_finite",
                                                  "saturated", "stall", "config", "protocol"};
  const int i = static_cast<int>(c);
  return i >= 0 && i < kFaultCodes ? kNames[i] : "unknown";
}

}  // namespace vines::link
