// GroundSource over the sample link: the samples vines_feed sends after the
// scene, read one per call (float or double on the wire, as the header says).
#pragma once

#include <cstdint>
#include <cstring>

#include "vines/hal/ground_source.hpp"
#include "vines/hal/port.hpp"

namespace vines::app {

class LinkSource final : public hal::GroundSource {
 public:
  LinkSource(double rate_hz, std::uint32_t samples, std::uint32_t sample_bytes)
      : rate_hz_(rate_hz), left_(samples), bytes_(sample_bytes) {}
  double rate_hz() const override { return rate_hz_; }
  bool next(double* accel_mps2) override {
    if (left_ == 0) return false;
    unsigned char raw[8];
    if (!hal::link_read(raw, bytes_)) {
      failed_ = true;
      return false;
    }
    --left_;
    if (bytes_ == 4) {
      float f;
      std::memcpy(&f, raw, 4);
      *accel_mps2 = static_cast<double>(f);
    } else {
      std::memcpy(accel_mps2, raw, 8);
    }
    return true;
  }
  bool failed() const { return failed_; }

 private:
  double rate_hz_;
  std::uint32_t left_;
  std::uint32_t bytes_;
  bool failed_ = false;
};

}  // namespace vines::app
