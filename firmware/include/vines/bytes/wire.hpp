// Little-endian field writer and reader over caller-owned buffers. Neither
// ever touches a byte outside its buffer: a write past the end or a read past
// the end sets a sticky flag (checked once after a whole message) instead.
// Doubles travel as their IEEE-754 bits, so values cross the link bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace vines::link {

class Writer {
 public:
  Writer(std::uint8_t* buf, std::size_t cap) : buf_(buf), cap_(cap) {}
  void u8(std::uint8_t v) { put(v, 1); }
  void u16(std::uint16_t v) { put(v, 2); }
  void u32(std::uint32_t v) { put(v, 4); }
  void u64(std::uint64_t v) { put(v, 8); }
  void f64(double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, 8);
    put(b, 8);
  }
  void bytes(const std::uint8_t* p, std::size_t n) {
    if (n > cap_ - len_) {
      overflow_ = true;
      return;
    }
    if (n == 0) return;  // an empty payload may come as a null pointer (memcpy must not get one)
    std::memcpy(buf_ + len_, p, n);
    len_ += n;
  }
  std::size_t size() const { return len_; }
  bool ok() const { return !overflow_; }

  // The wire layouts' operations (messages.hpp), the Reader's mirror images:
  // a value out of its range sets the sticky flag, as an overflow does.
  void field(std::uint8_t v) { u8(v); }
  void field(std::uint16_t v) { u16(v); }
  void field(std::uint32_t v) { u32(v); }
  void field(std::uint64_t v) { u64(v); }
  void field(double v) { f64(v); }
  // An enumeration as one byte, 0..last.
  template <class E>
  void enumeration(E v, E last) {
    if (static_cast<std::uint8_t>(v) > static_cast<std::uint8_t>(last)) overflow_ = true;
    u8(static_cast<std::uint8_t>(v));
  }
  // A count of what follows, 1..max.
  void count(std::uint8_t n, int max) {
    if (n < 1 || n > max) overflow_ = true;
    u8(n);
  }
  // A byte both sides know (a table's length): the reader refuses another.
  void constant(std::uint8_t v) { u8(v); }
  // A value out of its range found by the layout itself.
  void fail() { overflow_ = true; }
  // A NUL-terminated text shorter than its buffer: length byte, characters.
  template <std::size_t L>
  void text(const char (&s)[L]) {
    std::size_t len = 0;
    while (len < L && s[len] != '\0') ++len;
    if (len >= L || len > 255) overflow_ = true;
    u8(static_cast<std::uint8_t>(len));
    bytes(reinterpret_cast<const std::uint8_t*>(s), len < L ? len : 0);
  }
  // The rest of the payload: n bytes, at most max.
  void tail(const std::uint8_t* p, std::uint16_t n, std::size_t max) {
    if (n > max) overflow_ = true;
    bytes(p, n);
  }

 private:
  void put(std::uint64_t v, std::size_t n) {
    if (n > cap_ - len_) {
      overflow_ = true;
      return;
    }
    for (std::size_t i = 0; i < n; ++i) buf_[len_++] = static_cast<std::uint8_t>(v >> (8 * i));
  }
  std::uint8_t* buf_;
  std::size_t cap_, len_ = 0;
  bool overflow_ = false;
};

class Reader {
 public:
  Reader(const std::uint8_t* buf, std::size_t n) : buf_(buf), n_(n) {}
  std::uint8_t u8() { return static_cast<std::uint8_t>(get(1)); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(get(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(get(4)); }
  std::uint64_t u64() { return get(8); }
  double f64() {
    const std::uint64_t b = get(8);
    double v;
    std::memcpy(&v, &b, 8);
    return v;
  }
  // Points at the next n bytes (nullptr and the error flag if there are fewer).
  const std::uint8_t* bytes(std::size_t n) {
    if (n > n_ - pos_) {
      error_ = true;
      return nullptr;
    }
    const std::uint8_t* p = buf_ + pos_;
    pos_ += n;
    return p;
  }
  std::size_t remaining() const { return n_ - pos_; }
  // Everything read was there, and nothing is left over.
  bool done() const { return !error_ && pos_ == n_; }
  bool ok() const { return !error_; }

  // The wire layouts' operations (messages.hpp): see Writer.
  void field(std::uint8_t& v) { v = u8(); }
  void field(std::uint16_t& v) { v = u16(); }
  void field(std::uint32_t& v) { v = u32(); }
  void field(std::uint64_t& v) { v = u64(); }
  void field(double& v) { v = f64(); }
  template <class E>
  void enumeration(E& v, E last) {
    const std::uint8_t b = u8();
    if (b > static_cast<std::uint8_t>(last)) error_ = true;
    else v = static_cast<E>(b);
  }
  void count(std::uint8_t& n, int max) {
    n = u8();
    if (n < 1 || n > max) error_ = true;
  }
  void constant(std::uint8_t v) {
    if (u8() != v) error_ = true;
  }
  void fail() { error_ = true; }
  template <std::size_t L>
  void text(char (&s)[L]) {
    const std::uint8_t len = u8();
    const std::uint8_t* m = len < L ? bytes(len) : nullptr;
    if (len >= L) error_ = true;
    for (std::size_t i = 0; i < L; ++i) s[i] = m && i < len ? static_cast<char>(m[i]) : '\0';
  }
  void tail(const std::uint8_t*& p, std::uint16_t& n, std::size_t max) {
    if (error_ || remaining() > max) {
      error_ = true;
      return;
    }
    n = static_cast<std::uint16_t>(remaining());
    p = bytes(n);
  }

 private:
  std::uint64_t get(std::size_t n) {
    if (n > n_ - pos_) {
      error_ = true;
      pos_ = n_;
      return 0;
    }
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(buf_[pos_++]) << (8 * i);
    return v;
  }
  const std::uint8_t* buf_;
  std::size_t n_, pos_ = 0;
  bool error_ = false;
};

}  // namespace vines::link
