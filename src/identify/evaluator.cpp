// Batch evaluation of the objective over worker threads and MPI ranks.
#include <algorithm>
#include <thread>

#include "internal.hpp"

namespace gmasim::identify_detail {

const BatchEvaluator::Memo* BatchEvaluator::recall(const std::vector<double>& u) const {
  for (const Memo& e : memo_)
    if (e.u == u) return &e;
  return nullptr;
}

std::vector<char> BatchEvaluator::run(const std::vector<std::vector<double>>& points,
                                      std::vector<std::vector<double>>& res) {
  const std::size_t P = points.size();
  // source[i]: the index in `fresh` of point i's evaluation, or -1 - (memo index).
  std::vector<std::vector<double>> fresh;
  std::vector<long> source(P);
  for (std::size_t i = 0; i < P; ++i) {
    if (const Memo* e = recall(points[i])) {
      source[i] = -1 - (e - memo_.data());
      continue;
    }
    const auto it = std::find(fresh.begin(), fresh.end(), points[i]);
    source[i] = it - fresh.begin();
    if (it == fresh.end()) fresh.push_back(points[i]);
  }
  std::vector<std::vector<double>> fresh_res;
  const std::vector<char> fresh_ok = evaluate(fresh, fresh_res);
  res.assign(P, {});
  std::vector<char> ok(P, 0);
  for (std::size_t i = 0; i < P; ++i) {
    if (source[i] < 0) {
      const Memo& e = memo_[static_cast<std::size_t>(-1 - source[i])];
      res[i] = e.r;
      ok[i] = e.ok;
    } else {
      res[i] = fresh_res[static_cast<std::size_t>(source[i])];
      ok[i] = fresh_ok[static_cast<std::size_t>(source[i])];
    }
  }
  reused_ += static_cast<long>(P - fresh.size());
  for (std::size_t k = 0; k < fresh.size(); ++k) {  // remembered after the copies above
    Memo e{std::move(fresh[k]), std::move(fresh_res[k]), fresh_ok[k]};
    if (memo_.size() < kMemo) {
      memo_.push_back(std::move(e));
    } else {
      memo_[memo_next_] = std::move(e);
      memo_next_ = (memo_next_ + 1) % kMemo;
    }
  }
  return ok;
}

std::vector<char> BatchEvaluator::evaluate(const std::vector<std::vector<double>>& points,
                                           std::vector<std::vector<double>>& res) {
  const std::size_t P = points.size();
  res.clear();
  if (P == 0) return {};  // every rank alike: nothing to share
  const std::size_t m = obj_.residual_count();
  const int R = comm_.size(), me = comm_.rank();
  res.assign(P, std::vector<double>(m, 0.0));
  std::vector<char> ok(P, 0);
  std::vector<std::size_t> mine;
  for (std::size_t i = 0; i < P; ++i)
    if (static_cast<int>(i % static_cast<std::size_t>(R)) == me) mine.push_back(i);

  // The points split into one contiguous share per worker thread, each share one batch
  // evaluation (Objective::residuals_batch: its points' records share SIMD lanes). Each worker
  // writes only its own points' slots; a result does not depend on the split.
  const std::size_t nt = std::min<std::size_t>(static_cast<std::size_t>(threads_), mine.size());
  auto work = [&](std::size_t t) {
    const std::size_t b = mine.size() * t / nt, e = mine.size() * (t + 1) / nt;
    std::vector<const double*> u;
    std::vector<double*> r;
    for (std::size_t k = b; k < e; ++k) {
      u.push_back(points[mine[k]].data());
      r.push_back(res[mine[k]].data());
    }
    const std::vector<char> done = obj_.residuals_batch(u, r);
    for (std::size_t k = b; k < e; ++k) {
      const std::size_t i = mine[k];
      ok[i] = done[k - b];
      if (!ok[i]) std::fill(res[i].begin(), res[i].end(), 0.0);
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < nt; ++t) pool.emplace_back(work, t);
  if (nt > 0) work(0);
  for (auto& t : pool) t.join();

  if (R > 1) {  // every slot is non-zero on exactly one rank: the sum is exact
    std::vector<double> flat(P * (m + 1), 0.0);
    for (std::size_t i : mine) {
      std::copy(res[i].begin(), res[i].end(),
                flat.begin() + static_cast<std::ptrdiff_t>(i * (m + 1)));
      flat[i * (m + 1) + m] = ok[i] ? 1.0 : 0.0;
    }
    comm_.allreduce_sum(flat.data(), flat.size());
    for (std::size_t i = 0; i < P; ++i) {
      std::copy(flat.begin() + static_cast<std::ptrdiff_t>(i * (m + 1)),
                flat.begin() + static_cast<std::ptrdiff_t>(i * (m + 1) + m), res[i].begin());
      ok[i] = flat[i * (m + 1) + m] > 0.5 ? 1 : 0;
    }
  }
  evaluations_ += static_cast<long>(P);
  return ok;
}

void global_best(Collective& comm, double& f, std::vector<double>& u) {
  if (comm.size() == 1) return;
  double neg = -f;
  comm.allreduce_max(&neg, 1);
  const double fmin = -neg;
  double owner = f == fmin ? static_cast<double>(comm.size() - comm.rank()) : 0.0;
  comm.allreduce_max(&owner, 1);
  const int root = comm.size() - static_cast<int>(owner);
  comm.broadcast(u.data(), u.size(), root);
  f = fmin;
}

bool any_rank(Collective& comm, bool flag) {
  double v = flag ? 1.0 : 0.0;
  comm.allreduce_max(&v, 1);
  return v > 0.5;
}

long sum_ranks(Collective& comm, long v) {
  double d = static_cast<double>(v);
  comm.allreduce_sum(&d, 1);
  return static_cast<long>(d);
}

}  // namespace gmasim::identify_detail
