// The streaming loader of model images: a board decodes an image chunk by
// chunk, as it arrives, straight into its static model, and refuses one that
// does not fit it with a message naming what differs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "vines/bytes/crc32.hpp"
#include "vines/image/codec.hpp"
#include "vines/image/fields.hpp"
#include "vines/image/header.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/model.hpp"

namespace vines::image {

namespace detail {

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