// Internal: the collectives identify() runs over a Communicator (gmasim/identify/identify.hpp): a
// single process, or MPI (OpenMPI) when the library is built with GMASIM_WITH_MPI. Only the
// main thread calls them (MPI_THREAD_FUNNELED); islands and evaluation threads never do.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "gmasim/identify/identify.hpp"

namespace gmasim::identify_detail {

class Collective : public Communicator {
 public:
  // Element-wise sum / max over ranks, in place; every rank gets the result.
  virtual void allreduce_sum(double* data, std::size_t n) = 0;
  virtual void allreduce_max(double* data, std::size_t n) = 0;
  virtual void broadcast(double* data, std::size_t n, int root) = 0;
  // Ring: sends `send` to rank+1, returns what rank-1 sent (the same size on every rank).
  virtual std::vector<double> ring_shift(const std::vector<double>& send) = 0;
  // Gathers one string per rank on root (others get an empty vector).
  virtual std::vector<std::string> gather(const std::string& s, int root) = 0;
  virtual void barrier() = 0;
};

// The collectives of `c`. Throws InputError if `c` was not made by make_serial_communicator()
// or make_mpi_communicator().
Collective& collective(Communicator& c);

}  // namespace gmasim::identify_detail
