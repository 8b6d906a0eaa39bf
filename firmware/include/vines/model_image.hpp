// Model images: a built Model<S, N, Dev> as a compact, versioned byte image,
// so that a board never builds its own model (no eigensolver, no matrix
// exponential, no Van Loan blocks on its stack): the host builds it
// (build_model), writes its image (write_image), and the board decodes the
// image chunk by chunk as it arrives straight into its static Model
// (Loader), then steps it as if it had built it.
//
// Image = header (kHeaderBytes, fixed) + body. Everything little-endian,
// written field by field (never a struct copied as bytes):
//   off size field
//    0   4   magic "VNMI"
//    4   2   version (kVersion)
//    6   1   scalar: 0 double, 1 float
//    7   1   sizeof(scalar)
//    8   2   stories N
//   10   1   device kind (DeviceKind: 0 none, 1 tmd, 2 vines)
//   11   1   contact law (ContactLaw) of a VI NES, 0xFF otherwise
//   12   4   total length of the image in bytes (header + body)
//   16   2   field count of the body
//   18   2   reserved, 0
//   20   4   layout check: CRC-32 of the body's field list (each field's wire
//            type and entry count), so a host and a node built from sources
//            whose field lists differ refuse each other's images
//   24   4   CRC-32 (link/crc32.hpp) of the whole image but these 4 bytes
// Body: the fields of visit_fields() below, in its order, each as its raw
// little-endian entries (double: IEEE-754 binary64 bits, float: binary32;
// bool: one byte 0/1; integers and enums: two's complement of their size);
// matrices column by column (Eigen's storage order).
//
// Padding: the host pads the modal vectors to its SIMD width
// (VINES_MODAL_LANES, see Layout in model.hpp), a board usually does not.
// The image carries the N real modes only (the physical size for the dense
// TMD form), so the body does not depend on the padding; the loader zeroes
// every padding entry (the built model's inert modes hold other
// coefficients, e.g. an identity step, that act on zeros either way).
//
// What is in the body: everything the loop reads (sim.hpp, substep.hpp,
// peaks.hpp, bounce.hpp through the device constants, the energy ledger,
// the outputs floor_displacements/velocities, absolute_accel and
// elastic_energy), and the device's design (TmdDesign, VinesDesign): a few
// doubles, read by absolute_accel (TMD k, c), the divergence guard (sphere
// radius) and host snapshots (the VI NES gap). Left out, reporting only and
// zeroed on load: frame, modal, nominal_modal (so a loaded model has no
// modal report; host Engine::info() documents what it then lacks).
//
// Adding a field (another LoopParams or DeviceModel member): one line in
// visit_fields at the marked spot (a contact law's coefficients come from
// its kernel: coefficients(), contact.hpp); the size, field count and
// layout check follow from it (a host and a node then need the same
// sources). A member
// added at the end of LoopParams or of the VI NES DeviceModel without its
// line stops the build (static_assert tripwires naming the last member
// carried: move them to the new one). Bump kVersion when the meaning of
// existing fields changes.
//
// Firmware rules: header-only, no heap, no exceptions, no RTTI, no OS call;
// the Loader holds a pointer to the model (keep the model static) and a few
// dozen bytes of state, never a copy of the image.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include <Eigen/Core>

#include "vines/contact_laws.hpp"
#include "vines/link/crc32.hpp"
#include "vines/model.hpp"

namespace vines::image {

inline constexpr std::uint16_t kVersion = 1;
inline constexpr std::size_t kHeaderBytes = 28;
inline constexpr std::uint8_t kMagic[4] = {'V', 'N', 'M', 'I'};
inline constexpr std::uint8_t kNoLaw = 0xFF;

// Which entries of a field travel: `runs` runs of `len` entries, run k
// starting at entry k * stride of the field's storage; the other entries are
// padding (not written, zeroed on load). len < 0: every entry.
struct Part {
  int runs, len, stride;
};

namespace detail {

// ---- entries and their wire form

template <typename T>
struct Entries {  // a plain member: one entry
  using type = std::remove_const_t<T>;
  static constexpr int count = 1;
  static T* data(T& x) { return &x; }
};
template <typename Sc, int R, int C, int O, int MR, int MC>
struct Entries<Eigen::Matrix<Sc, R, C, O, MR, MC>> {
  using type = Sc;
  static_assert(R > 0 && C > 0, "image fields are fixed-size");
  static_assert(R == 1 || C == 1 || !(O & Eigen::RowMajor), "image matrices are column-major");
  static constexpr int count = R * C;
  static Sc* data(Eigen::Matrix<Sc, R, C, O, MR, MC>& x) { return x.data(); }
};
template <typename Sc, int R, int C, int O, int MR, int MC>
struct Entries<const Eigen::Matrix<Sc, R, C, O, MR, MC>> {
  using type = Sc;
  static constexpr int count = R * C;
  static const Sc* data(const Eigen::Matrix<Sc, R, C, O, MR, MC>& x) { return x.data(); }
};

// Wire form of an entry type: its size and a code for the layout check.
template <typename T>
struct Wire {
  static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>, "image fields hold numbers");
  static constexpr std::size_t bytes = std::is_same_v<T, bool> ? 1 : sizeof(T);
  static_assert(bytes == 1 || bytes == 2 || bytes == 4 || bytes == 8, "unsupported entry size");
  static_assert(!std::is_floating_point_v<T> || std::is_same_v<T, float> || std::is_same_v<T, double>,
                "floating-point entries are float or double");
  static constexpr std::uint8_t code = static_cast<std::uint8_t>(
      (std::is_floating_point_v<T> ? 0x10 : std::is_same_v<T, bool> ? 0x20 : 0x30) | bytes);

  static void put(T v, std::uint8_t* b) {
    std::uint64_t u = 0;
    if constexpr (std::is_same_v<T, bool>) {
      u = v ? 1u : 0u;
    } else if constexpr (bytes == 8) {
      std::uint64_t x;
      std::memcpy(&x, &v, 8);
      u = x;
    } else if constexpr (bytes == 4) {
      std::uint32_t x;
      std::memcpy(&x, &v, 4);
      u = x;
    } else if constexpr (bytes == 2) {
      std::uint16_t x;
      std::memcpy(&x, &v, 2);
      u = x;
    } else {
      std::uint8_t x;
      std::memcpy(&x, &v, 1);
      u = x;
    }
    for (std::size_t i = 0; i < bytes; ++i) b[i] = static_cast<std::uint8_t>(u >> (8 * i));
  }
  static T get(const std::uint8_t* b) {
    std::uint64_t u = 0;
    for (std::size_t i = 0; i < bytes; ++i) u |= static_cast<std::uint64_t>(b[i]) << (8 * i);
    T v{};
    if constexpr (std::is_same_v<T, bool>) {
      v = u != 0;
    } else if constexpr (bytes == 8) {
      std::memcpy(&v, &u, 8);
    } else if constexpr (bytes == 4) {
      const std::uint32_t x = static_cast<std::uint32_t>(u);
      std::memcpy(&v, &x, 4);
    } else if constexpr (bytes == 2) {
      const std::uint16_t x = static_cast<std::uint16_t>(u);
      std::memcpy(&v, &x, 2);
    } else {
      const std::uint8_t x = static_cast<std::uint8_t>(u);
      std::memcpy(&v, &x, 1);
    }
    return v;
  }
};

// The member at the end of a chain of member pointers (m.*a.*b...).
template <typename T>
struct MemberOf;
template <typename T, typename C>
struct MemberOf<T C::*> {
  using type = T;
};
template <typename P, typename... Ps>
struct Last : Last<Ps...> {};
template <typename P>
struct Last<P> {
  using type = P;
};
template <typename... Ps>
using FieldOf = typename MemberOf<typename Last<Ps...>::type>::type;

template <typename Obj, typename P>
auto& member(Obj& o, P p) {
  return o.*p;
}
template <typename Obj, typename P, typename Q, typename... Ps>
auto& member(Obj& o, P p, Q q, Ps... ps) {
  return member(o.*p, q, ps...);
}

constexpr Part resolve(Part p, int count) { return p.len < 0 ? Part{1, count, count} : p; }
constexpr int storage_index(const Part& p, int i) { return i / p.len * p.stride + i % p.len; }

constexpr std::uint32_t crc_update(std::uint32_t crc, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i)
    crc = link::detail::kCrcTable[(crc ^ static_cast<std::uint32_t>(v >> (8 * i))) & 0xFFu] ^ (crc >> 8);
  return crc;
}

}  // namespace detail

// ---- the body: one list of fields for the writer, the loader and the sizes

// Calls v(part, &Model::a, &A::b, ...) for every field of the body, in
// order; the visitor applies the chain of member pointers to its model (the
// counting visitor to none: sizes come from the types, so image_bytes() is
// a constant).
template <typename S, int N, typename Dev, typename V>
constexpr void visit_fields(V& v) {
  using M = Model<S, N, Dev>;
  using L = typename M::LtiT;
  using Q = typename M::QuadT;
  using F = typename M::FormT;
  using Rows = ModalRows<S, M::kP>;
  using Boundary = ModalForm<S, M::kP>;
  using DM = DeviceModel<S, Dev>;
  constexpr int P = M::kP;
  constexpr int R = M::kModal ? N : P;  // real modes (modal), every coordinate (dense)
  constexpr Part all{1, -1, -1};
  constexpr Part modes{1, R, P};        // a vector over the position coordinates
  constexpr Part halves{2, R, P};       // a state vector [positions; velocities]
  constexpr Part floor_map{1, N * R, N * P};  // N x P, column by column

  // Loop settings, field by field.
  v(all, &M::loop, &LoopParams::sensor_rate_hz);
  v(all, &M::loop, &LoopParams::contact_rtol);
  v(all, &M::loop, &LoopParams::max_substeps_per_step);
  v(all, &M::loop, &LoopParams::contact_count_depth_m);
  v(all, &M::loop, &LoopParams::energy_ledger);
  v(all, &M::loop, &LoopParams::floor_peaks);
  v(all, &M::loop, &LoopParams::divergence_limit_m);
  v(all, &M::loop, &LoopParams::contact_scheme);
  v(all, &M::loop, &LoopParams::bounded_substeps);
  // New LoopParams fields here, one line each:
  //   v(all, &M::loop, &LoopParams::new_field);
  // Tripwire: a field added at the end of LoopParams without its line here
  // stops the build (then name the new last field below).
  static_assert(sizeof(LoopParams) == offsetof(LoopParams, bounded_substeps) + sizeof(int),
                "LoopParams has a field after bounded_substeps: add its line to visit_fields");

  v(all, &M::h);
  v(all, &M::floor);
  v(all, &M::hs);

  // Exact step of the linear part.
  if constexpr (M::kModal) {
    for (auto f : {&L::p11, &L::p12, &L::p21, &L::p22, &L::gx0, &L::gx1, &L::gv0, &L::gv1, &L::ak, &L::ac, &L::bgv,
                   &L::bfv})
      v(modes, &M::lti, f);
  } else {
    v(all, &M::lti, &L::phi);
    for (auto f : {&L::g0, &L::g1}) v(all, &M::lti, f);
  }
  // Step integrals (E_e, input work, damping) and instantaneous forms.
  for (auto q : {&M::strain_step, &M::input_step, &M::damping_step}) {
    if constexpr (M::kModal) {
      for (auto f : {&Q::qq, &Q::qv, &Q::vv, &Q::q0, &Q::q1, &Q::v0, &Q::v1}) v(modes, q, f);
      for (auto f : {&Q::c00, &Q::c01, &Q::c11}) v(all, q, f);
    } else {
      v(all, q, &Q::w);
    }
  }
  for (auto q : {&M::kinetic, &M::strain, &M::device_potential, &M::damping_power, &M::input_power}) {
    if constexpr (M::kModal) {
      for (auto f : {&F::qq, &F::qv, &F::vv, &F::qa, &F::va}) v(modes, q, f);
      v(all, q, &F::aa);
      v(all, q, &F::positions_only);
    } else {
      v(all, q, &F::q);
    }
  }
  // Readouts.
  v(floor_map, &M::pos_map);
  for (auto f : {&Rows::top, &Rows::dev, &Rows::bound, &Rows::lq0, &Rows::lq1, &Rows::lv0, &Rows::lv1})
    v(modes, &M::rows, f);
  for (auto f : {&Rows::l00, &Rows::l01, &Rows::l11}) v(all, &M::rows, f);
  v(all, &M::rows, &Rows::dev_is_top);
  v(all, &M::ee_lyapunov);
  for (auto f : {&Boundary::qq, &Boundary::qv, &Boundary::vv, &Boundary::qa, &Boundary::va})
    v(modes, &M::ee_boundary, f);
  v(all, &M::ee_boundary, &Boundary::aa);
  v(all, &M::ee_boundary, &Boundary::positions_only);
  v(halves, &M::top_acc_z);
  v(all, &M::top_acc_ag);
  v(all, &M::minv_k);
  v(all, &M::minv_c);
  v(all, &M::inv_floor_mass);

  // The device.
  if constexpr (Dev::kKind == DeviceKind::kTmd) {
    for (auto f : {&TmdDesign::mass, &TmdDesign::k, &TmdDesign::c, &TmdDesign::mu, &TmdDesign::lambda, &TmdDesign::xi,
                   &TmdDesign::omega})
      v(all, &M::dev, &DM::design, f);
    v(all, &M::dev, &DM::x0);
    v(all, &M::dev, &DM::v0);
  }
  if constexpr (Dev::kKind == DeviceKind::kVines) {
    using D = VinesDesign;
    using Law = decltype(DM::law);
    for (auto f : {&D::mass, &D::radius, &D::box_length, &D::gap, &D::c, &D::m_star, &D::eps, &D::tau, &D::v_ref, &D::g})
      v(all, &M::dev, &DM::design, f);
    v(all, &M::dev, &DM::design, &D::ok);
    for (auto f : {&DM::m, &DM::m_star, &DM::inv_m, &DM::wall_left, &DM::wall_right, &DM::y0, &DM::v0, &DM::c,
                   &DM::eps})
      v(all, &M::dev, f);
    // The law's coefficients, as its kernel lists them (contact_laws.hpp).
    Law::coefficients([&](auto coefficient) { v(all, &M::dev, &DM::law, coefficient); });
    for (auto f : {&DM::pos_scale, &DM::vel_scale, &DM::modal_scale, &DM::q_scale, &DM::w_step0, &DM::ff_a0,
                   &DM::ff_a1, &DM::ff_v, &DM::count_depth, &DM::event_tol, &DM::round_tol, &DM::clear_lo,
                   &DM::clear_hi})
      v(all, &M::dev, f);
    // New DeviceModel fields of the VI NES here, one line each:
    //   v(all, &M::dev, &DM::new_field);
    // Tripwire, as for LoopParams (a field small enough to hide in the end
    // padding of one scalar shows in the other).
    static_assert(sizeof(DM) == (offsetof(DM, clear_hi) + sizeof(S) + alignof(DM) - 1) / alignof(DM) * alignof(DM),
                  "DeviceModel (VI NES) has a field after clear_hi: add its line to visit_fields");
  }
}

namespace detail {

// Sizes and layout check of the body, from the field list alone.
struct Counter {
  std::size_t bytes = 0;
  int fields = 0;
  std::uint32_t crc = 0xFFFFFFFFu;
  bool fits = true;  // every Part lies within its field

  template <typename... Ps>
  constexpr void operator()(Part part, Ps...) {
    using E = Entries<FieldOf<Ps...>>;
    using T = typename E::type;
    const Part p = resolve(part, E::count);
    if (p.runs < 1 || p.len < 1 || (p.runs > 1 && p.len > p.stride) || (p.runs - 1) * p.stride + p.len > E::count)
      fits = false;
    const int n = p.runs * p.len;
    bytes += static_cast<std::size_t>(n) * Wire<T>::bytes;
    ++fields;
    crc = crc_update(crc, Wire<T>::code, 1);
    crc = crc_update(crc, static_cast<std::uint32_t>(n), 4);
  }
};

struct Shape {
  std::size_t body;
  int fields;
  std::uint32_t layout;
  bool fits;
};

template <typename S, int N, typename Dev>
constexpr Shape shape() {
  Counter c;
  visit_fields<S, N, Dev>(c);
  return {c.bytes, c.fields, ~c.crc, c.fits};
}

// Writes the body of a model.
template <typename M>
struct BodyWriter {
  const M* m;
  std::uint8_t* out;
  std::size_t pos = 0;

  template <typename... Ps>
  void operator()(Part part, Ps... path) {
    const auto& f = member(*m, path...);
    using E = Entries<std::remove_reference_t<decltype(f)>>;
    using T = typename E::type;
    const Part p = resolve(part, E::count);
    const T* d = E::data(f);
    for (int i = 0; i < p.runs * p.len; ++i, pos += Wire<T>::bytes) Wire<T>::put(d[storage_index(p, i)], out + pos);
  }
};

// Zeroes every entry of every field (padding included).
template <typename M>
struct Zeroer {
  M* m;
  template <typename... Ps>
  void operator()(Part, Ps... path) {
    auto& f = member(*m, path...);
    using E = Entries<std::remove_reference_t<decltype(f)>>;
    using T = typename E::type;
    T* d = E::data(f);
    for (int i = 0; i < E::count; ++i) d[i] = T{};
  }
};

// Decodes the body bytes [lo, hi) (at src) into the model's fields. An
// entry cut by the end of a chunk is assembled in `part` across calls.
template <typename M>
struct BodyDecoder {
  M* m;
  const std::uint8_t* src;
  std::size_t lo, hi;
  std::uint8_t* part;
  std::size_t off = 0;  // where the current field starts in the body

  template <typename... Ps>
  void operator()(Part part_of, Ps... path) {
    auto& f = member(*m, path...);
    using E = Entries<std::remove_reference_t<decltype(f)>>;
    using T = typename E::type;
    constexpr std::size_t w = Wire<T>::bytes;
    const Part p = resolve(part_of, E::count);
    const std::size_t n = static_cast<std::size_t>(p.runs * p.len), start = off;
    off += n * w;
    if (off <= lo || start >= hi) return;
    T* d = E::data(f);
    for (std::size_t i = start >= lo ? 0 : (lo - start) / w; i < n; ++i) {
      const std::size_t eo = start + i * w;
      if (eo >= hi) break;
      const std::size_t b0 = eo > lo ? eo : lo, b1 = eo + w < hi ? eo + w : hi;
      for (std::size_t b = b0; b < b1; ++b) part[b - eo] = src[b - lo];
      if (eo + w <= hi) d[storage_index(p, static_cast<int>(i))] = Wire<T>::get(part);
    }
  }
};

template <typename S>
constexpr std::uint8_t scalar_code() {
  static_assert(std::is_same_v<S, double> || std::is_same_v<S, float>, "images hold double or float models");
  return std::is_same_v<S, float> ? 1 : 0;
}
template <typename Dev>
constexpr std::uint8_t law_code() {
  if constexpr (Dev::kKind == DeviceKind::kVines) return static_cast<std::uint8_t>(Dev::kLaw);
  else return kNoLaw;
}

inline void put_u16(std::uint8_t* b, std::uint16_t v) {
  b[0] = static_cast<std::uint8_t>(v);
  b[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_u32(std::uint8_t* b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline std::uint16_t get_u16(const std::uint8_t* b) { return static_cast<std::uint16_t>(b[0] | (b[1] << 8)); }
inline std::uint32_t get_u32(const std::uint8_t* b) {
  return static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
         static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
}

inline const char* device_text(std::uint8_t kind) {
  switch (kind) {
    case static_cast<std::uint8_t>(DeviceKind::kNone): return "none";
    case static_cast<std::uint8_t>(DeviceKind::kTmd): return "tmd";
    case static_cast<std::uint8_t>(DeviceKind::kVines): return "vines";
    default: return nullptr;
  }
}
// A message assembled in a caller's buffer (no printf: integers only).
class Text {
 public:
  Text(char* buf, std::size_t cap) : buf_(buf), cap_(cap) { buf_[0] = '\0'; }
  Text& s(const char* t) {
    while (*t && len_ + 1 < cap_) buf_[len_++] = *t++;
    buf_[len_] = '\0';
    return *this;
  }
  Text& u(std::uint64_t v, int base = 10) {
    char d[24];
    int n = 0;
    do {
      const unsigned r = static_cast<unsigned>(v % static_cast<unsigned>(base));
      d[n++] = static_cast<char>(r < 10 ? '0' + r : 'a' + (r - 10));
      v /= static_cast<unsigned>(base);
    } while (v && n < 24);
    if (base == 16) s("0x");
    char t[2] = {0, 0};
    while (n) {
      t[0] = d[--n];
      s(t);
    }
    return *this;
  }
  // "tmd", "vines (kuwabara)", "device 9"...
  Text& device(std::uint8_t kind, std::uint8_t law) {
    const char* k = device_text(kind);
    if (!k) return s("an unknown device (code ").u(kind).s(")");
    s(k);
    if (kind != static_cast<std::uint8_t>(DeviceKind::kVines))
      return law == kNoLaw ? *this : s(" (law code ").u(law).s(")");
    const char* l = law_name(static_cast<ContactLaw>(law));
    if (!l) return s(" (law code ").u(law).s(")");
    return s(" (").s(l).s(")");
  }

 private:
  char* buf_;
  std::size_t cap_, len_ = 0;
};

}  // namespace detail

// Bytes of the image of this instance (header + body).
template <typename S, int N, typename Dev>
constexpr std::size_t image_bytes() {
  constexpr detail::Shape sh = detail::shape<S, N, Dev>();
  static_assert(sh.fits, "visit_fields: a Part does not fit its field");
  return kHeaderBytes + sh.body;
}

// The header of an image as written (for tools that describe an image; the
// Loader checks it against its instance). false: fewer than kHeaderBytes or
// no magic.
struct HeaderInfo {
  std::uint16_t version = 0;
  std::uint8_t scalar = 0, scalar_bytes = 0;  // scalar: 0 double, 1 float
  std::uint16_t stories = 0;
  std::uint8_t device = 0, law = kNoLaw;      // DeviceKind, ContactLaw (kNoLaw: no VI NES)
  std::uint32_t length = 0;                   // header + body
  std::uint16_t fields = 0;
  std::uint32_t layout = 0, crc = 0;
};
inline bool read_header(const std::uint8_t* p, std::size_t n, HeaderInfo* out) {
  if (p == nullptr || n < kHeaderBytes || std::memcmp(p, kMagic, 4) != 0) return false;
  out->version = detail::get_u16(p + 4);
  out->scalar = p[6];
  out->scalar_bytes = p[7];
  out->stories = detail::get_u16(p + 8);
  out->device = p[10];
  out->law = p[11];
  out->length = detail::get_u32(p + 12);
  out->fields = detail::get_u16(p + 16);
  out->layout = detail::get_u32(p + 20);
  out->crc = detail::get_u32(p + 24);
  return true;
}

// Writes the image of a built model; returns its size, 0 if cap is too small.
template <typename S, int N, typename Dev>
std::size_t write_image(const Model<S, N, Dev>& m, std::uint8_t* out, std::size_t cap) {
  constexpr detail::Shape sh = detail::shape<S, N, Dev>();
  constexpr std::size_t total = image_bytes<S, N, Dev>();
  static_assert(total <= 0xFFFFFFFFu && sh.fields <= 0xFFFF, "image too large for its header");
  if (out == nullptr || cap < total) return 0;
  std::memcpy(out, kMagic, 4);
  detail::put_u16(out + 4, kVersion);
  out[6] = detail::scalar_code<S>();
  out[7] = static_cast<std::uint8_t>(sizeof(S));
  detail::put_u16(out + 8, static_cast<std::uint16_t>(N));
  out[10] = static_cast<std::uint8_t>(Dev::kKind);
  out[11] = detail::law_code<Dev>();
  detail::put_u32(out + 12, static_cast<std::uint32_t>(total));
  detail::put_u16(out + 16, static_cast<std::uint16_t>(sh.fields));
  detail::put_u16(out + 18, 0);
  detail::put_u32(out + 20, sh.layout);
  detail::BodyWriter<Model<S, N, Dev>> w{&m, out + kHeaderBytes};
  visit_fields<S, N, Dev>(w);
  if (w.pos != sh.body) return 0;  // cannot happen: the sizes come from the same list
  const std::uint32_t crc = link::crc32(out + kHeaderBytes, total - kHeaderBytes, link::crc32(out, 24));
  detail::put_u32(out + 24, crc);
  return total;
}

// Streaming loader: the image arrives in chunks, in order, and is decoded
// straight into the model's storage (no staging buffer the size of the
// image). The model is overwritten from the first body byte on: it is usable
// only once finish() succeeded (ready()), whatever happened before; a
// refused image leaves it unusable (not ready) until a good one loads.
// Refusals are sticky until reset(); messages point into the loader.
template <typename S, int N, typename Dev>
class Loader {
 public:
  explicit Loader(Model<S, N, Dev>* m) : m_(m) { reset(); }

  // Start over; the model is not ready.
  void reset() {
    state_ = State::kHeader;
    got_ = 0;
    crc_ = 0;
    err_ = nullptr;
    msg_[0] = '\0';
  }

  // nullptr, or why the image is refused (the header is checked as soon as
  // it is in).
  const char* push(const std::uint8_t* p, std::size_t n) {
    if (state_ == State::kRefused) return err_;
    if (state_ == State::kReady) return refuse("model image: longer than its header says");
    if (n == 0) return nullptr;
    if (p == nullptr) return refuse("model image: no data (null chunk)");
    if (state_ == State::kHeader) {
      const std::size_t take = n < kHeaderBytes - got_ ? n : kHeaderBytes - got_;
      std::memcpy(head_ + got_, p, take);
      got_ += take;
      p += take;
      n -= take;
      if (got_ < kHeaderBytes) return nullptr;
      if (const char* e = check_header()) return refuse(e);
      start_body();
      if (n == 0) return nullptr;
    }
    constexpr std::size_t total = image_bytes<S, N, Dev>();
    if (n > total - got_) return refuse("model image: longer than its header says");
    detail::BodyDecoder<Model<S, N, Dev>> d{m_, p, got_ - kHeaderBytes, got_ - kHeaderBytes + n, part_};
    visit_fields<S, N, Dev>(d);
    crc_ = link::crc32(p, n, crc_);
    got_ += n;
    return nullptr;
  }

  // After the last byte: nullptr when the image is complete and its CRC
  // holds (the model is then ready), else why not.
  const char* finish() {
    if (state_ == State::kRefused) return err_;
    if (state_ == State::kReady) return nullptr;
    constexpr std::size_t total = image_bytes<S, N, Dev>();
    if (got_ < total) {
      detail::Text t(msg_, sizeof msg_);
      t.s("model image: truncated (").u(got_).s(" of ").u(total).s(" bytes)");
      return refuse(msg_);
    }
    if (crc_ != expected_crc_) return refuse("model image: CRC mismatch");
    state_ = State::kReady;
    return nullptr;
  }

  // finish() succeeded since the last reset().
  bool ready() const { return state_ == State::kReady; }

 private:
  enum class State : std::uint8_t { kHeader, kBody, kReady, kRefused };

  const char* refuse(const char* why) {
    state_ = State::kRefused;
    err_ = why;
    return err_;
  }

  // What in the header does not fit this node, most basic first (nullptr:
  // it fits). Messages with numbers are assembled in msg_.
  const char* check_header() {
    constexpr detail::Shape sh = detail::shape<S, N, Dev>();
    constexpr std::size_t total = image_bytes<S, N, Dev>();
    const std::uint8_t* h = head_;
    detail::Text t(msg_, sizeof msg_);
    if (std::memcmp(h, kMagic, 4) != 0) return "model image: not a model image (no VNMI magic)";
    const std::uint16_t version = detail::get_u16(h + 4);
    if (version != kVersion) {
      t.s("model image: version ").u(version).s(", this node reads ").u(kVersion);
      return msg_;
    }
    const char* here = sizeof(S) == 4 ? "float" : "double";
    if (h[6] > 1) {
      t.s("model image: unknown scalar code ").u(h[6]);
      return msg_;
    }
    if (h[6] != detail::scalar_code<S>()) {
      t.s("model image: built for ").s(h[6] ? "float" : "double").s(", this node runs ").s(here);
      return msg_;
    }
    if (h[7] != sizeof(S)) {
      t.s("model image: scalar of ").u(h[7]).s(" bytes, this node's ").s(here).s(" has ").u(sizeof(S));
      return msg_;
    }
    const std::uint16_t stories = detail::get_u16(h + 8);
    if (stories != N) {
      t.s("model image: ").u(stories).s(" stories, this node is built for ").u(N);
      return msg_;
    }
    if (h[10] != static_cast<std::uint8_t>(Dev::kKind) || h[11] != detail::law_code<Dev>()) {
      t.s("model image: device ").device(h[10], h[11]).s(", this node runs ");
      t.device(static_cast<std::uint8_t>(Dev::kKind), detail::law_code<Dev>());
      return msg_;
    }
    const std::uint32_t length = detail::get_u32(h + 12);
    if (length != total) {
      t.s("model image: ").u(length).s(" bytes, this node expects ").u(total);
      t.s(" (fields differ: host and node built from other sources)");
      return msg_;
    }
    const std::uint16_t fields = detail::get_u16(h + 16);
    const std::uint32_t layout = detail::get_u32(h + 20);
    if (fields != sh.fields || layout != sh.layout) {
      t.s("model image: field layout ").u(layout, 16).s(" (").u(fields).s(" fields), this node's is ");
      t.u(sh.layout, 16).s(" (").u(static_cast<std::uint64_t>(sh.fields));
      t.s(" fields): host and node built from other sources");
      return msg_;
    }
    if (detail::get_u16(h + 18) != 0) return "model image: reserved header bytes are not zero";
    return nullptr;
  }

  // Header accepted: clear the model (padding entries and the reporting-only
  // parts stay zero), start the CRC.
  void start_body() {
    detail::Zeroer<Model<S, N, Dev>> z{m_};
    visit_fields<S, N, Dev>(z);
#if VINES_MODEL_REPORT
    Model<S, N, Dev>& m = *m_;
    m.frame.m.setZero();
    m.frame.k.setZero();
    m.frame.K.setZero();
    m.frame.C.setZero();
    for (Modal<N>* mo : {&m.modal, &m.nominal_modal}) {
      mo->omega.setZero();
      mo->zeta.setZero();
      mo->gamma.setZero();
      mo->m_eff.setZero();
      mo->phi.setZero();
    }
#endif
    expected_crc_ = detail::get_u32(head_ + 24);
    crc_ = link::crc32(head_, 24);
    state_ = State::kBody;
  }

  Model<S, N, Dev>* m_;
  State state_ = State::kHeader;
  std::size_t got_ = 0;  // bytes received, header included
  std::uint32_t crc_ = 0, expected_crc_ = 0;
  const char* err_ = nullptr;
  std::uint8_t head_[kHeaderBytes] = {};
  std::uint8_t part_[8] = {};  // an entry cut across two chunks
  char msg_[160] = {};
};

}  // namespace vines::image
