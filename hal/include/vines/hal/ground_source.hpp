// HAL facade: where ground-acceleration samples come from, and what time it is.
// The loop is fed through these two interfaces; each build picks a backend
// (host: record files and a simulated clock, every host run fed by
// sim_host/run/drive.hpp; MCU: the link's frames and a hardware timer).
// No virtual destructors: a deleting destructor would drag operator delete
// (the heap) into the MCU image. Owners destroy concrete types.
#pragma once

#include <cstddef>
#include <cstdint>

namespace vines::hal {

// Samples of ground acceleration [m/s^2] at a fixed sensor rate. Sample k is
// the acceleration at t = k / rate_hz(), starting with k = 0 at t = 0.
class GroundSource {
 public:
  virtual double rate_hz() const = 0;
  // Writes the next sample and returns true, or returns false at the end of
  // the stream (or on a fault the backend reports through its own status).
  virtual bool next(double* accel_mps2) = 0;
  // Up to n next samples into out[0..); returns how many (fewer only at the
  // end of the stream). A backend with its samples in memory copies them.
  virtual std::size_t read(double* out, std::size_t n) {
    std::size_t k = 0;
    while (k < n && next(out + k)) ++k;
    return k;
  }

 protected:
  ~GroundSource() = default;
};

// Monotonic time in nanoseconds. The host's simulated clock advances by one
// sensor period per sample it hands out, so runs are reproducible.
class Clock {
 public:
  virtual std::uint64_t now_ns() const = 0;

 protected:
  ~Clock() = default;
};

}  // namespace vines::hal
