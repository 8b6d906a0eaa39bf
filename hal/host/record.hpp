// Host HAL backend: ground-motion records read from files, resampled to the
// sensor rate, and handed out one sample at a time with a simulated clock.
// Host-only code: it may allocate and throw; the firmware never sees it.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "vines/hal/ground_source.hpp"

namespace vines::hal {

enum class Units { kG, kMps2, kCmps2 };

enum class RecordFormat {
  kAuto,       // PEER AT2 if the header says NPTS/DT, else columns
  kAt2,        // PEER AT2 (legacy and NGA headers, any spacing around '=')
  kTimeAccel,  // whitespace columns: time, then one or more acceleration columns
  kAccel,      // acceleration values only (any count per line); needs dt
};

struct RecordSpec {
  std::string path;
  RecordFormat format = RecordFormat::kAuto;
  Units units = Units::kG;  // AT2 files say their own units (g)
  double dt_s = 0.0;        // kAccel only
  int column = 1;           // kTimeAccel: which acceleration column (1 = first after time)
  double scale = 1.0;       // multiplies every sample (after unit conversion)
};

// A uniformly sampled record in m/s^2: sample i is at t0_s + i * dt_s.
struct Record {
  std::string path;
  double dt_s = 0.0;
  double t0_s = 0.0;
  std::vector<double> accel_mps2;
  double duration_s() const { return dt_s * static_cast<double>(accel_mps2.size()); }
  double pga_mps2() const;  // largest |a|
};

// Every problem with a record file, with a message naming the file and, where
// it applies, the line: "path:LINE: what is wrong".
class RecordError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Limits of an input file (docs in hal/README.md): the largest real record of
// ../shared/data/ground_motions is 0.4 MB and 8,171 points, so these are far
// beyond any real record (80x, 250x) and keep a runaway file's memory bounded.
inline constexpr std::uintmax_t kMaxRecordBytes = 32u << 20;  // 32 MiB
inline constexpr std::size_t kMaxRecordPoints = 2'000'000;    // lines and values
inline constexpr double kMinRecordDt = 1e-6;  // s: a 1 MHz record
inline constexpr double kMaxRecordDt = 1.0;   // s: slower cannot describe ground shaking

// The whole content of `path`, which must be a regular file (not a folder, a
// device such as /dev/zero, a FIFO or a terminal) of at most max_bytes.
// std::runtime_error "path: why" otherwise (the system's reason included).
std::string read_input_file(const std::string& path, std::uintmax_t max_bytes);

// Reads and checks a record: missing, empty, not regular or oversize file,
// non-numeric or non-finite values, too many points, NPTS that disagrees with
// the values read, a non-uniform or non-increasing time column, a dt outside
// [kMinRecordDt, kMaxRecordDt], a record ending after 3600 s are all
// RecordErrors.
Record load_record(const RecordSpec& spec);

// Same checks on the file's text already in memory (the fuzzer, tests):
// spec.path only names the record in messages.
Record parse_record(const std::string& text, const RecordSpec& spec);

// m/s^2 per unit.
double unit_factor(Units u);

// The same limits on a record built in memory (a Python array): at least
// one sample, every one finite, the point count, dt and end time as for a
// file; RecordError naming record.path otherwise.
void check_record(const Record& record);

// The format of a record file as kAuto would read it: kAt2 if an NPTS/DT
// header line is in its first lines, else kTimeAccel for two or more columns,
// kAccel for one. RecordError if the file cannot be read.
RecordFormat detect_record_format(const std::string& path);

// Samples the record's piecewise-linear acceleration at t_k = k / rate_hz for
// k = 0 .. round(duration * rate_hz). The record is taken as zero after its
// last sample (it ends at t0 + N dt) and before t0.
std::vector<double> resample(const Record& record, double rate_hz);

// Simulated monotonic clock: starts at 0 and advances only when told to.
class SimClock final : public Clock {
 public:
  std::uint64_t now_ns() const override { return now_ns_; }
  void advance_ns(std::uint64_t dt_ns) { now_ns_ += dt_ns; }

 private:
  std::uint64_t now_ns_ = 0;
};

// Feeds resampled samples at the sensor rate; each next() advances the clock
// by one sensor period (the first sample is at t = 0). A view: the samples
// (an excitation's, shared by the runs of a study) outlive the source.
class RecordSource final : public GroundSource {
 public:
  RecordSource(const double* samples_mps2, std::size_t n, double rate_hz, SimClock* clock = nullptr);
  RecordSource(const std::vector<double>& samples_mps2, double rate_hz, SimClock* clock = nullptr)
      : RecordSource(samples_mps2.data(), samples_mps2.size(), rate_hz, clock) {}
  RecordSource(std::vector<double>&&, double, SimClock* = nullptr) = delete;  // would dangle
  double rate_hz() const override { return rate_hz_; }
  bool next(double* accel_mps2) override;
  std::size_t read(double* out, std::size_t n) override;
  std::size_t size() const { return n_; }
  std::size_t position() const { return pos_; }

 private:
  void advance_clock(std::size_t from, std::size_t to);  // from sample `from`'s time to `to`'s
  const double* samples_;
  std::size_t n_;
  double rate_hz_;
  SimClock* clock_;
  std::size_t pos_ = 0;
};

}  // namespace vines::hal
