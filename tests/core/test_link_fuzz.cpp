// Deterministic fuzzing of the link decoder and node (the same body as the
// libFuzzer target, fuzz/link_decoder_fuzz.cpp): random bytes, and valid
// sessions mutated by flips, insertions, deletions, duplicated and swapped
// spans. Under the debug preset it runs with AddressSanitizer and UBSan.
#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <vector>

#include "link_fuzz_body.hpp"

namespace vines::link {
namespace {

void put(std::vector<std::uint8_t>* s, MsgType type, std::uint16_t seq, const std::uint8_t* p, std::size_t n) {
  std::uint8_t w[kMaxWire];
  const std::size_t len = encode_frame(type, seq, p, n, w, sizeof w);
  s->insert(s->end(), w, w + len);
}

// A valid session: a model image (two chunks; the toy plant takes any
// bytes), the settings (two chunks), start, samples, stop.
std::vector<std::uint8_t> session(std::mt19937& rng) {
  std::vector<std::uint8_t> s;
  NodeConfig c;
  c.scene.frame.stories = static_cast<int>(1 + rng() % kMaxStories);
  for (int i = 0; i < c.scene.frame.stories; ++i) {
    c.scene.frame.mass_kg[i] = 1e5;
    c.scene.frame.stiffness_n_per_m[i] = 1e8;
  }
  c.scene.loop.sensor_rate_hz = 1000;
  c.sensor_range_mps2 = 50;
  c.mode = static_cast<NodeMode>(rng() % 3);
  std::uint8_t blob[kMaxConfigBlob], p[kMaxPayload];
  const std::size_t n = encode(c, blob, sizeof blob);
  std::uint16_t seq = 0;
  std::uint8_t image[300];
  for (auto& b : image) b = static_cast<std::uint8_t>(rng());
  for (std::size_t off = 0; off < sizeof image; off += kChunk) {
    ConfigureChunk ch{ConfigPart::kModelImage, static_cast<std::uint32_t>(off), sizeof image,
                      crc32(image, sizeof image), image + off,
                      static_cast<std::uint16_t>(std::min(kChunk, sizeof image - off))};
    put(&s, MsgType::kConfigure, seq++, p, encode(ch, p, sizeof p));
  }
  for (std::size_t off = 0; off < n; off += kChunk) {
    ConfigureChunk ch{ConfigPart::kSettings, static_cast<std::uint32_t>(off), static_cast<std::uint32_t>(n),
                      crc32(blob, n), blob + off, static_cast<std::uint16_t>(std::min(kChunk, n - off))};
    put(&s, MsgType::kConfigure, seq++, p, encode(ch, p, sizeof p));
  }
  put(&s, MsgType::kStart, seq++, p, encode(Start{0, 0}, p, sizeof p));
  std::normal_distribution<double> a(0, 3);
  for (std::uint32_t k = 0; k < 40; ++k)
    put(&s, MsgType::kSample, seq++, p, encode(Sample{k, k * 1000000ull, a(rng), a(rng)}, p, sizeof p));
  put(&s, MsgType::kStop, seq++, p, 0);
  return s;
}

void mutate(std::vector<std::uint8_t>* s, std::mt19937& rng) {
  const int edits = 1 + rng() % 8;
  for (int e = 0; e < edits && !s->empty(); ++e) {
    const std::size_t i = rng() % s->size(), len = 1 + rng() % std::min<std::size_t>(64, s->size() - i);
    switch (rng() % 5) {
      case 0: (*s)[i] ^= static_cast<std::uint8_t>(1u << (rng() % 8)); break;
      case 1: s->insert(s->begin() + i, static_cast<std::uint8_t>(rng())); break;
      case 2: s->erase(s->begin() + i, s->begin() + i + len); break;
      case 3: {
        const std::vector<std::uint8_t> span(s->begin() + i, s->begin() + i + len);
        s->insert(s->begin() + rng() % s->size(), span.begin(), span.end());
        break;
      }
      default: {
        const std::size_t j = rng() % s->size();
        std::swap((*s)[i], (*s)[j]);
      }
    }
  }
}

TEST(LinkFuzz, RandomBytesAndMutatedSessions) {
  std::mt19937 rng(2024);
  const auto t0 = std::chrono::steady_clock::now();
  int runs = 0;
  for (; runs < 3000; ++runs) {
    std::vector<std::uint8_t> in;
    if (runs % 4 == 0) {
      in.resize(rng() % 2048);
      for (auto& b : in) b = static_cast<std::uint8_t>(rng() % (runs % 8 == 0 ? 4 : 256));
    } else {
      in = session(rng);
      mutate(&in, rng);
    }
    ASSERT_EQ(fuzz::run_one(in.data(), in.size()), 0u) << "run " << runs;
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(s, 120.0) << "no input may take long (hang)";
}

TEST(LinkFuzz, AnUnmutatedSessionRunsEverySample) {
  std::mt19937 rng(1);
  const auto in = session(rng);
  fuzz::ToyPlant plant;
  fuzz::CheckingSink sink;
  Node<fuzz::ToyPlant, fuzz::CheckingSink> node(&plant, &sink);
  for (std::uint8_t b : in) node.on_byte(b, 0);
  EXPECT_EQ(sink.bad, 0u);
  EXPECT_TRUE(node.stopped());
  EXPECT_EQ(node.status().steps, 40u);
  int faults = 0;
  for (std::uint32_t f : node.status().faults) faults += static_cast<int>(f);
  EXPECT_EQ(faults, 0);
}

}  // namespace
}  // namespace vines::link
