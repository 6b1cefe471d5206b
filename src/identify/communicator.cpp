// The thin communication layer of identify(): a single process, or MPI (OpenMPI) when the
// library is built with GMASIM_WITH_MPI. Only the main thread calls MPI (MPI_THREAD_FUNNELED);
// islands and evaluation threads never do.
#include "identify/communicator.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "gmasim/errors.hpp"

#ifdef GMASIM_WITH_MPI
#include <mpi.h>
#endif

namespace gmasim {
namespace {

using identify_detail::Collective;

class SerialCommunicator final : public Collective {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void allreduce_sum(double*, std::size_t) override {}
  void allreduce_max(double*, std::size_t) override {}
  void broadcast(double*, std::size_t, int) override {}
  std::vector<double> ring_shift(const std::vector<double>& send) override { return send; }
  std::vector<std::string> gather(const std::string& s, int) override { return {s}; }
  void barrier() override {}
  [[noreturn]] void abort(int code) override { std::exit(code); }
};

#ifdef GMASIM_WITH_MPI
void check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) throw std::runtime_error(std::string("MPI error in ") + what);
}

class MpiCommunicator final : public Collective {
 public:
  MpiCommunicator(int* argc, char*** argv) {
    int inited = 0;
    MPI_Initialized(&inited);
    if (!inited) {
      int provided = 0;
      check(MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
      owns_ = true;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiCommunicator() override {
    if (owns_) {
      int finalized = 0;
      MPI_Finalized(&finalized);
      if (!finalized) MPI_Finalize();
    }
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void allreduce_sum(double* d, std::size_t n) override {
    if (size_ > 1)
      check(
          MPI_Allreduce(MPI_IN_PLACE, d, static_cast<int>(n), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD),
          "MPI_Allreduce");
  }
  void allreduce_max(double* d, std::size_t n) override {
    if (size_ > 1)
      check(
          MPI_Allreduce(MPI_IN_PLACE, d, static_cast<int>(n), MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD),
          "MPI_Allreduce");
  }
  void broadcast(double* d, std::size_t n, int root) override {
    if (size_ > 1)
      check(MPI_Bcast(d, static_cast<int>(n), MPI_DOUBLE, root, MPI_COMM_WORLD), "MPI_Bcast");
  }
  std::vector<double> ring_shift(const std::vector<double>& send) override {
    if (size_ == 1) return send;
    std::vector<double> recv(send.size());
    const int next = (rank_ + 1) % size_, prev = (rank_ + size_ - 1) % size_;
    check(MPI_Sendrecv(send.data(), static_cast<int>(send.size()), MPI_DOUBLE, next, 17,
                       recv.data(), static_cast<int>(recv.size()), MPI_DOUBLE, prev, 17,
                       MPI_COMM_WORLD, MPI_STATUS_IGNORE),
          "MPI_Sendrecv");
    return recv;
  }
  std::vector<std::string> gather(const std::string& s, int root) override {
    if (size_ == 1) return {s};
    int len = static_cast<int>(s.size());
    std::vector<int> lens(static_cast<std::size_t>(size_)), displs(static_cast<std::size_t>(size_));
    check(MPI_Gather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, root, MPI_COMM_WORLD),
          "MPI_Gather");
    std::vector<char> buf;
    if (rank_ == root) {
      int total = 0;
      for (int r = 0; r < size_; ++r) {
        displs[static_cast<std::size_t>(r)] = total;
        total += lens[static_cast<std::size_t>(r)];
      }
      buf.resize(static_cast<std::size_t>(total) + 1);
    }
    check(MPI_Gatherv(s.data(), len, MPI_CHAR, buf.data(), lens.data(), displs.data(), MPI_CHAR,
                      root, MPI_COMM_WORLD),
          "MPI_Gatherv");
    std::vector<std::string> out;
    if (rank_ == root) {
      for (int r = 0; r < size_; ++r) {
        out.emplace_back(buf.data() + displs[static_cast<std::size_t>(r)],
                         static_cast<std::size_t>(lens[static_cast<std::size_t>(r)]));
      }
    }
    return out;
  }
  void barrier() override {
    if (size_ > 1) MPI_Barrier(MPI_COMM_WORLD);
  }
  [[noreturn]] void abort(int code) override {
    MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
  }

 private:
  int rank_ = 0, size_ = 1;
  bool owns_ = false;
};
#endif

}  // namespace

Collective& identify_detail::collective(Communicator& c) {
  auto* own = dynamic_cast<Collective*>(&c);
  if (own == nullptr)
    throw InputError(
        "IdentifyOptions::comm: use make_serial_communicator() or make_mpi_communicator()");
  return *own;
}

std::unique_ptr<Communicator> make_serial_communicator() {
  return std::make_unique<SerialCommunicator>();
}

bool mpi_compiled() {
#ifdef GMASIM_WITH_MPI
  return true;
#else
  return false;
#endif
}

bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE",
                        "MPI_LOCALNRANKS", "MV2_COMM_WORLD_SIZE"}) {
    if (std::getenv(v) != nullptr) return true;
  }
  return false;
}

std::unique_ptr<Communicator> make_mpi_communicator(int* argc, char*** argv) {
#ifdef GMASIM_WITH_MPI
  return std::make_unique<MpiCommunicator>(argc, argv);
#else
  (void)argc;
  (void)argv;
  throw InputError("this gmasim was built without MPI (GMASIM_WITH_MPI=OFF): run without mpirun");
#endif
}

}  // namespace gmasim
