// The byte form of a loop's state (Engine::state, Engine::load_state): a
// header that says whose state it is, then the engine's blocks as they lie in
// memory (host byte order: a state is for engines of this build, not a file
// format to exchange).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "sim_host/scene/scalar.hpp"
#include "vines/model/contact_laws.hpp"
#include "vines/model/devices.hpp"

namespace vines::host::loop_state {

inline constexpr char kMagic[8] = {'v', 'i', 'n', 'e', 's', 'L', 'S', '\0'};
inline constexpr std::uint32_t kVersion = 1;

// What a state says about the engine it came from.
struct Header {
  char magic[8];
  std::uint32_t version;
  std::uint32_t stories;
  std::uint8_t scalar;  // Scalar
  std::uint8_t device;  // DeviceKind
  std::uint8_t law;     // ContactLaw (VI NES), else 0
  std::uint8_t pad[5];
  std::uint64_t block_bytes;  // the blocks after the header
  std::uint64_t model;        // FNV-1a 64 of the model image
};
static_assert(std::is_trivially_copyable_v<Header> && sizeof(Header) == 40, "the header is 40 bytes, no padding");

// FNV-1a, 64 bits.
inline std::uint64_t fnv1a64(const std::uint8_t* p, std::size_t n) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

// A model's fingerprint, hashed from its image once after each change of the
// model (forget() on build, new initial conditions, a loaded image): hashing
// the image is 30 us on the 10-story VI NES, six steps' worth.
class Fingerprint {
 public:
  void forget() { known_ = false; }
  template <class Engine>
  std::uint64_t of(const Engine& e) const {
    if (!known_) {
      const std::vector<std::uint8_t> image = e.model_image();
      value_ = fnv1a64(image.data(), image.size());
      known_ = true;
    }
    return value_;
  }

 private:
  mutable std::uint64_t value_ = 0;
  mutable bool known_ = false;
};

// The header of an engine of (scalar, N, Dev) with blocks of `bytes` on the
// model of fingerprint `model`.
template <int N, typename Dev>
Header header_of(Scalar scalar, std::size_t bytes, std::uint64_t model) {
  Header h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.version = kVersion;
  h.stories = static_cast<std::uint32_t>(N);
  h.scalar = static_cast<std::uint8_t>(scalar);
  h.device = static_cast<std::uint8_t>(Dev::kKind);
  if constexpr (Dev::kKind == DeviceKind::kVines) h.law = static_cast<std::uint8_t>(Dev::kLaw);
  h.block_bytes = bytes;
  h.model = model;
  return h;
}

// "10 stories, double, vines (kuwabara)" (the scene's names; scene/names.hpp
// is not for the engines' units, which do not see the records' headers).
inline std::string engine_name(const Header& h) {
  const DeviceKind kind = static_cast<DeviceKind>(h.device);
  const char* device = kind == DeviceKind::kTmd ? "tmd" : kind == DeviceKind::kVines ? "vines" : "none";
  std::string s = std::to_string(h.stories) + " stories, " + scalar_name(static_cast<Scalar>(h.scalar)) + ", " + device;
  if (kind == DeviceKind::kVines) {
    const char* law = law_name(static_cast<ContactLaw>(h.law));
    s += std::string(" (") + (law ? law : "an unknown law") + ")";
  }
  return s;
}

// Where an engine keeps one block of its state.
struct Slot {
  void* p;
  std::size_t n;
};

// A state: the header, then each slot's bytes in turn.
template <class Slots>
std::vector<std::uint8_t> write(const Header& h, const Slots& slots) {
  std::vector<std::uint8_t> out(sizeof(Header) + h.block_bytes);
  std::memcpy(out.data(), &h, sizeof(Header));
  std::size_t at = sizeof(Header);
  for (const Slot& s : slots) {
    std::memcpy(out.data() + at, s.p, s.n);
    at += s.n;
  }
  return out;
}

// Reads the blocks of a state check() accepted into their slots, in turn.
template <class Slots>
void read(const std::uint8_t* p, const Slots& slots) {
  std::size_t at = sizeof(Header);
  for (const Slot& s : slots) {
    std::memcpy(s.p, p + at, s.n);
    at += s.n;
  }
}

// Empty if p[0..n) is a state with header `want` (this engine's), else why
// not; the blocks then start at p + sizeof(Header). With any_model, a state
// of another model of the same engine is accepted (Engine::take_over).
inline std::string check(const Header& want, const std::uint8_t* p, std::size_t n, bool any_model = false) {
  const std::size_t total = sizeof(Header) + want.block_bytes;
  if (n < sizeof kMagic) return n && std::memcmp(p, kMagic, n) == 0 ? "truncated" : "not a vines loop state";
  if (std::memcmp(p, kMagic, sizeof kMagic) != 0) return "not a vines loop state";
  if (n < sizeof(Header))
    return "truncated: " + std::to_string(n) + " bytes, not even the " + std::to_string(sizeof(Header)) +
           "-byte header";
  Header h;
  std::memcpy(&h, p, sizeof h);
  if (h.version != kVersion)
    return "a vines loop state of version " + std::to_string(h.version) + " (this program reads version " +
           std::to_string(kVersion) + ")";
  if (h.stories != want.stories || h.scalar != want.scalar || h.device != want.device || h.law != want.law)
    return "a state of another engine (" + engine_name(h) + "; this one: " + engine_name(want) + ")";
  if (h.block_bytes != want.block_bytes)
    return "a state of another build (" + std::to_string(h.block_bytes) + " bytes of data; this engine's: " +
           std::to_string(want.block_bytes) + ")";
  if (!any_model && h.model != want.model) {
    char why[128];
    std::snprintf(why, sizeof why, "a state of another model (fingerprint %016llx; this engine's: %016llx)",
                  static_cast<unsigned long long>(h.model), static_cast<unsigned long long>(want.model));
    return why;
  }
  if (n < total) return "truncated: " + std::to_string(n) + " of " + std::to_string(total) + " bytes";
  if (n > total)
    return "not a vines loop state: " + std::to_string(n - total) + (n - total == 1 ? " byte" : " bytes") +
           " past its end (" + std::to_string(total) + " bytes)";
  return {};
}

}  // namespace vines::host::loop_state
