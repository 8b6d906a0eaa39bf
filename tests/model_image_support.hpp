// Shared by the model-image tests (test_model_image*.cpp): blocks that start
// dirty, a built model, its image, a chunked load, bit-for-bit comparison of
// two runs, the head of El Centro.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "support.hpp"
#include "vines/build/build_model.hpp"
#include "vines/image/model_image.hpp"
#include "vines/step/sim.hpp"

namespace vines::image_test {


using Bytes = std::vector<std::uint8_t>;
using Kuwabara = VinesDevice<ContactLaw::kKuwabara>;

// Heap blocks whose storage is filled with 0xFF before construction: every
// member without an initialiser (most of a Model) starts as NaN or -1, so a
// loaded model owes nothing to what the storage held.
template <typename T>
struct FreeDirty {
  void operator()(T* p) const {
    p->~T();
    ::operator delete(p, std::align_val_t(alignof(T)));
  }
};
template <typename T>
using Dirty = std::unique_ptr<T, FreeDirty<T>>;
template <typename T>
Dirty<T> dirty() {
  void* raw = ::operator new(sizeof(T), std::align_val_t(alignof(T)));
  std::memset(raw, 0xFF, sizeof(T));
  return Dirty<T>(new (raw) T);
}

template <typename S, typename Dev>
Dirty<Model<S, 10, Dev>> built(const SceneParams& p) {
  auto m = dirty<Model<S, 10, Dev>>();
  const ParamError e = build_model(p, m.get());
  EXPECT_TRUE(e.ok()) << e.field << ": " << e.message;
  return m;
}

template <typename S, int N, typename Dev>
Bytes image_of(const Model<S, N, Dev>& m) {
  Bytes b(image::image_bytes<S, N, Dev>());
  b.resize(image::write_image(m, b.data(), b.size()));
  return b;
}

// Pushes `bytes` in chunks of `chunk` then finishes: "" if the loader ends
// ready, else the first refusal. The loader must be ready exactly when
// nothing was refused.
template <typename S, int N, typename Dev>
std::string load(image::Loader<S, N, Dev>& ld, const Bytes& bytes, std::size_t chunk) {
  ld.reset();
  std::string why;
  for (std::size_t i = 0; i < bytes.size() && why.empty(); i += chunk) {
    const std::size_t n = std::min(chunk, bytes.size() - i);
    if (const char* e = ld.push(bytes.data() + i, n)) why = e;
  }
  if (why.empty())
    if (const char* e = ld.finish()) why = e;
  EXPECT_EQ(ld.ready(), why.empty()) << why;
  return why;
}

// ---- bit-for-bit comparison of two runs

template <typename T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}
template <typename Sc, int R, int C, int O, int MR, int MC>
bool same_bits(const Eigen::Matrix<Sc, R, C, O, MR, MC>& a, const Eigen::Matrix<Sc, R, C, O, MR, MC>& b) {
  for (int i = 0; i < a.size(); ++i)
    if (!same_bits(a.data()[i], b.data()[i])) return false;
  return true;
}

// The first part of the data blocks (and the outputs read off them) that
// differs in any bit, or nullptr.
template <typename S, int N, typename Dev>
const char* first_difference(const Model<S, N, Dev>& ma, const Data<S, N, Dev>& a, const Model<S, N, Dev>& mb,
                             const Data<S, N, Dev>& b) {
#define VINES_SAME(x) \
  if (!same_bits(a.x, b.x)) return #x
  VINES_SAME(z);
  VINES_SAME(s);
  VINES_SAME(sd);
  VINES_SAME(xt);
  VINES_SAME(vt);
  VINES_SAME(xf);
  VINES_SAME(vf);
  VINES_SAME(k);
  VINES_SAME(peak_top);
  VINES_SAME(peak_top_velocity);
  VINES_SAME(peak_top_k);
  VINES_SAME(peak_top_dt);
  VINES_SAME(ee_sum);
  VINES_SAME(ee_open);
  VINES_SAME(a_prev);
  VINES_SAME(mode);
  VINES_SAME(substep);
  VINES_SAME(substep_w);
  VINES_SAME(q);
  VINES_SAME(contact_force);
  VINES_SAME(contact_depth);
  VINES_SAME(max_overlap);
  VINES_SAME(peak_x);
  VINES_SAME(peak_drift);
  VINES_SAME(strain_increments);
  VINES_SAME(last_strain);
  VINES_SAME(ledger.initial);
  VINES_SAME(ledger.input);
  VINES_SAME(ledger.damping);
  VINES_SAME(ledger.contact);
  VINES_SAME(ledger.kinetic);
  VINES_SAME(ledger.strain);
  VINES_SAME(ledger.device);
  VINES_SAME(ledger.residual);
  VINES_SAME(ledger.max_abs_residual);
  VINES_SAME(ledger.max_input);
  VINES_SAME(count.steps);
  VINES_SAME(count.careful_steps);
  VINES_SAME(count.substeps);
  VINES_SAME(count.contact_substeps);
  VINES_SAME(count.rejected);
  VINES_SAME(count.events);
  VINES_SAME(count.contacts);
  VINES_SAME(count.cap_hits);
  VINES_SAME(count.max_substeps_in_step);
  VINES_SAME(count.bad_samples);
  VINES_SAME(count.divergences);
#undef VINES_SAME
  if (!same_bits(floor_displacements(ma, a), floor_displacements(mb, b))) return "floor displacements";
  if (!same_bits(floor_velocities(ma, a), floor_velocities(mb, b))) return "floor velocities";
  if (!same_bits(absolute_accel(ma, a), absolute_accel(mb, b))) return "absolute accelerations";
  if (!same_bits(elastic_energy(ma, a), elastic_energy(mb, b))) return "E_e";
  return nullptr;
}

// The first seconds of El Centro (docs/model.md section 6) at 1 kHz.
inline const std::vector<double>& elcentro_head() {
  static const std::vector<double> a = [] {
    std::vector<double> all = test::elcentro(1000.0);
    all.resize(5001);  // 5 s
    return all;
  }();
  return a;
}

// ---- every instance: build -> bytes -> load in chunks -> the same steps

// A shipped scene file.
inline std::string scene_file(const char* name) { return std::string(VINES_SOURCE_DIR) + "/data/scenes/" + name; }

// A built model, its image, and a dirty model with a loader to load it into.
template <typename S, typename Dev>
struct Fixture {
  Dirty<Model<S, 10, Dev>> ref, target = dirty<Model<S, 10, Dev>>();
  Bytes img;
  image::Loader<S, 10, Dev> ld{target.get()};
  explicit Fixture(const SceneParams& p) : ref(built<S, Dev>(p)), img(image_of(*ref)) {}
};

}  // namespace vines::image_test
