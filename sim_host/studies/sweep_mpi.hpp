// MPI for `vines sweep` when the build has it (VINES_HAVE_MPI) and the program
// was started by mpirun: each rank runs every size()-th run from rank(), then
// rank 0 gathers the result set. Otherwise a single rank of one.
#pragma once

#include <vector>

#include "sim_host/studies/sweep.hpp"

namespace vines::host {

class Mpi {
 public:
  Mpi();
  ~Mpi();
  Mpi(const Mpi&) = delete;
  Mpi& operator=(const Mpi&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  // Collects every rank's finished runs into rank 0's vector.
  void gather(std::vector<RunResult>* results) const;
  // Whether every rank says ok (each rank waits for all).
  bool all(bool ok) const;

 private:
  int rank_ = 0, size_ = 1;
  bool active_ = false;
};

}  // namespace vines::host
