// run_on_ranks (commands.hpp): the launch of the commands that run on MPI ranks (identify,
// design, sweep --grid).
#include <fmt/format.h>

#include <algorithm>
#include <memory>
#include <thread>

#include "commands.hpp"
#include "gmasim/identify/identify.hpp"

namespace gmasim::cli {
namespace {

// MPI's abort ends every rank without returning to main(), whose cleanup of a failed command's
// empty output directories therefore runs here first.
void abort_ranks(Communicator& comm, int code) {
  remove_created_output_dirs_if_empty();
  comm.abort(code);
}

}  // namespace

int threads_per_rank(int requested, const Communicator& comm) {
  if (requested < 0)
    throw InputError(fmt::format("--threads {}: must be 0 (all cores) or >= 1", requested));
  if (requested > 0) return requested;
  const int local =
      std::max(1, env_int("OMPI_COMM_WORLD_LOCAL_SIZE", comm.size() > 1 ? comm.size() : 1));
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / local);
}

int run_on_ranks(const std::string& mpi, const std::string& command,
                 const std::function<int(Communicator&)>& body) {
  const bool launched = launched_by_mpi();
  const bool use_mpi = mpi == "on" || (mpi == "auto" && launched);
  if (!use_mpi && launched && env_int("OMPI_COMM_WORLD_SIZE", 1) > 1)
    throw InputError(
        mpi_compiled()
            ? fmt::format("{}: launched by mpirun with --mpi off: every rank would run the same "
                          "work and write the same files",
                          command)
            : fmt::format("{}: launched by mpirun, but this gmasim was built without MPI",
                          command));
  std::unique_ptr<Communicator> comm =
      use_mpi ? make_mpi_communicator(nullptr, nullptr) : make_serial_communicator();
  try {
    return body(*comm);
  } catch (const InputError& e) {
    if (comm->rank() == 0) print_error(e.what());
    if (comm->size() > 1) abort_ranks(*comm, 2);
    return 2;  // main() removes the empty output directories of a failed command
  } catch (const std::exception& e) {
    print_error(fmt::format("internal error (rank {}): {}", comm->rank(), e.what()));
    if (comm->size() > 1) abort_ranks(*comm, 4);
    return 4;
  }
}

}  // namespace gmasim::cli
