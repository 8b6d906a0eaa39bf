#include "sim_host/sweep_mpi.hpp"

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
  std::int64_t index, contacts, cap_hits;
  double x_r, E_r, peak_top, elastic_energy, residual;
  char device[8];
  char error[224];
};

bool launched_by_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr;
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

void Mpi::gather(std::vector<RunResult>* results) const {
  if (!active_) return;
  std::vector<Packed> mine;
  for (std::size_t i = 0; i < results->size(); ++i) {
    const RunResult& r = (*results)[i];
    if (!r.done) continue;
    Packed p{};
    p.index = static_cast<std::int64_t>(i);
    p.contacts = r.contacts;
    p.cap_hits = r.cap_hits;
    p.x_r = r.x_r;
    p.E_r = r.E_r;
    p.peak_top = r.peak_top;
    p.elastic_energy = r.elastic_energy;
    p.residual = r.residual;
    std::strncpy(p.device, r.device.c_str(), sizeof p.device - 1);
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
    r.contacts = p.contacts;
    r.cap_hits = p.cap_hits;
    r.x_r = p.x_r;
    r.E_r = p.E_r;
    r.peak_top = p.peak_top;
    r.elastic_energy = p.elastic_energy;
    r.residual = p.residual;
    r.device = p.device;
    r.error = p.error;
  }
}

#else

Mpi::Mpi() = default;
Mpi::~Mpi() = default;
void Mpi::gather(std::vector<RunResult>*) const {}

#endif

}  // namespace vines::host
