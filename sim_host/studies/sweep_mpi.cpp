#include "sim_host/studies/sweep_mpi.hpp"

#include <cstdlib>
#include <cstring>

#ifdef VINES_HAVE_MPI
#include <mpi.h>
#endif

namespace vines::host {

#ifdef VINES_HAVE_MPI
namespace {

// A finished run as plain bytes.
struct Packed {
  std::int64_t index, contacts, cap_hits, bad_samples, divergences;
  double x_r, E_r, peak_top, elastic_energy, residual, max_overlap;
  bool energy_checked, degraded;
  char device[8];
  char degraded_reasons[320];  // every code of both runs fits
  char error[224];
};

bool launched_by_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr;
}

// The numbers of a result, copied to or from its packed form.
template <class From, class To>
void copy_numbers(const From& from, To* to) {
  to->contacts = from.contacts;
  to->cap_hits = from.cap_hits;
  to->x_r = from.x_r;
  to->E_r = from.E_r;
  to->peak_top = from.peak_top;
  to->elastic_energy = from.elastic_energy;
  to->residual = from.residual;
  to->bad_samples = from.bad_samples;
  to->divergences = from.divergences;
  to->max_overlap = from.max_overlap;
  to->energy_checked = from.energy_checked;
  to->degraded = from.degraded;
}

}  // namespace

Mpi::Mpi() {
  if (!launched_by_mpirun()) return;
  MPI_Init(nullptr, nullptr);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  active_ = true;
}

Mpi::~Mpi() {
  if (active_) MPI_Finalize();
}

bool Mpi::all(bool ok) const {
  if (!active_) return ok;
  int mine = ok ? 1 : 0, every = 0;
  MPI_Allreduce(&mine, &every, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
  return every != 0;
}

void Mpi::gather(std::vector<RunResult>* results) const {
  if (!active_) return;
  std::vector<Packed> mine;
  for (std::size_t i = 0; i < results->size(); ++i) {
    const RunResult& r = (*results)[i];
    if (!r.done) continue;
    Packed p{};
    p.index = static_cast<std::int64_t>(i);
    copy_numbers(r, &p);
    std::strncpy(p.device, r.device.c_str(), sizeof p.device - 1);
    std::strncpy(p.degraded_reasons, r.degraded_reasons.c_str(), sizeof p.degraded_reasons - 1);
    std::strncpy(p.error, r.error.c_str(), sizeof p.error - 1);
    mine.push_back(p);
  }
  const int bytes = static_cast<int>(mine.size() * sizeof(Packed));
  std::vector<int> counts(size_), displs(size_);
  MPI_Gather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::vector<Packed> all;
  if (rank_ == 0) {
    int total = 0;
    for (int r = 0; r < size_; ++r) {
      displs[r] = total;
      total += counts[r];
    }
    all.resize(static_cast<std::size_t>(total) / sizeof(Packed));
  }
  MPI_Gatherv(mine.data(), bytes, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, 0,
              MPI_COMM_WORLD);
  for (const Packed& p : all) {
    RunResult& r = (*results)[static_cast<std::size_t>(p.index)];
    r.done = true;
    copy_numbers(p, &r);
    r.device = p.device;
    r.degraded_reasons = p.degraded_reasons;
    r.error = p.error;
  }
}

#else

Mpi::Mpi() = default;
Mpi::~Mpi() = default;
void Mpi::gather(std::vector<RunResult>*) const {}
bool Mpi::all(bool ok) const { return ok; }

#endif

}  // namespace vines::host
