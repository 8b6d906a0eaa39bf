// The byte codec of model images (model_image.hpp describes the format):
// which entries of a field travel (Part), the wire form of an entry (Wire:
// little-endian, field by field, never a struct copied as bytes), chains of
// member pointers, and the visitors that size, write, zero and decode a body
// from the field list (fields.hpp). Firmware rules: no heap, no exceptions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include <Eigen/Core>

#include "vines/bytes/crc32.hpp"

namespace vines::image {

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

// ---- the visitors of a body's field list (fields.hpp)

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

// ---- the header's integers (little-endian)

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

}  // namespace detail

}  // namespace vines::image
