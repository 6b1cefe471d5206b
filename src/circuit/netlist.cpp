#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/model/circuit.hpp"
#include "gmasim/physics/stages.hpp"

namespace gmasim {

// The fixed part of the nodal matrix and the precomputed pieces of the low-rank (Woodbury)
// solve (gmasim/model/circuit.hpp).
struct CircuitMatrices {
  Eigen::MatrixXd fixed_laplacian;  // contribution of the fixed-reluctance branches
  // Low-rank pieces, when Circuit::lowrank.enabled:
  Eigen::MatrixXd W;            // G0^-1 B            (n x k)
  Eigen::MatrixXd S;            // B^T G0^-1 B        (k x k)
  Eigen::VectorXd psi_coil;     // G0^-1 b per ampere of coil current (fixed branches)
  Eigen::VectorXd psi_pm;       // G0^-1 b per unit PM scale (fixed branches)
  Eigen::VectorXd Bt_psi_coil;  // B^T psi_coil (k)
  Eigen::VectorXd Bt_psi_pm;    // B^T psi_pm (k)
  // The same k x k pieces in plain fixed storage for the step's hot path (rod_solve): S row-major
  // with stride 8, and B^T psi_coil, B^T psi_pm.
  std::array<double, 64> S8{};
  std::array<double, 8> bt_coil8{}, bt_pm8{};
};

using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 8, 1>;

// A workspace's Eigen buffers, sized once by CircuitWorkspace::resize.
struct NodalBuffers {
  Eigen::MatrixXd G;
  Eigen::VectorXd rhs;  // holds the node potentials psi after a solve
  Eigen::LLT<Eigen::MatrixXd> llt;
  SmallVector z;  // low-rank path: the rod branches' fluxes
};

NodalBuffersPtr::NodalBuffersPtr() = default;
NodalBuffersPtr::~NodalBuffersPtr() = default;
NodalBuffersPtr::NodalBuffersPtr(const NodalBuffersPtr& other)
    : p_(other.p_ ? std::make_unique<NodalBuffers>(*other.p_) : nullptr) {}
NodalBuffersPtr& NodalBuffersPtr::operator=(const NodalBuffersPtr& other) {
  if (this != &other) p_ = other.p_ ? std::make_unique<NodalBuffers>(*other.p_) : nullptr;
  return *this;
}
NodalBuffersPtr::NodalBuffersPtr(NodalBuffersPtr&& other) noexcept = default;
NodalBuffersPtr& NodalBuffersPtr::operator=(NodalBuffersPtr&& other) noexcept = default;
void NodalBuffersPtr::reset(std::unique_ptr<NodalBuffers> p) { p_ = std::move(p); }

namespace {

// Adds a branch of conductance g between its nodes to a nodal (Laplacian) matrix.
void stamp_conductance(Eigen::MatrixXd& G, const CircuitBranch& br, double g) {
  if (br.from >= 0) G(br.from, br.from) += g;
  if (br.to >= 0) G(br.to, br.to) += g;
  if (br.from >= 0 && br.to >= 0) {
    G(br.from, br.to) -= g;
    G(br.to, br.from) -= g;
  }
}

// Checks every branch (two distinct nodes; a rod index in range and in one branch only; a
// positive reluctance otherwise) and maps each rod to its branch (c.rod_branch).
void map_rod_branches(Circuit& c, int rod_count, const std::string& where) {
  c.rod_branch.assign(static_cast<std::size_t>(rod_count), -1);
  for (std::size_t b = 0; b < c.branches.size(); ++b) {
    const auto& br = c.branches[b];
    if (br.from == br.to)
      throw InputError(located(
          where, 0, fmt::format("circuit branch '{}' starts and ends at the same node", br.name)));
    if (br.rod >= 0) {
      if (br.rod >= rod_count)
        throw InputError(located(where, 0,
                                 fmt::format("circuit branch '{}' names rod index {} of {}",
                                             br.name, br.rod, rod_count)));
      if (c.rod_branch[static_cast<std::size_t>(br.rod)] >= 0)
        throw InputError(
            located(where, 0, fmt::format("rod index {} appears in two circuit branches", br.rod)));
      c.rod_branch[static_cast<std::size_t>(br.rod)] = static_cast<int>(b);
    } else if (!(br.fixed_reluctance_per_H > 0.0)) {
      throw InputError(
          located(where, 0,
                  fmt::format("circuit branch '{}' has reluctance {} 1/H; it must be > 0", br.name,
                              br.fixed_reluctance_per_H)));
    }
  }
  for (int r = 0; r < rod_count; ++r)
    if (c.rod_branch[static_cast<std::size_t>(r)] < 0)
      throw InputError(located(where, 0, fmt::format("rod index {} is in no circuit branch", r)));
}

// Every node must be joined to the reference by a path of branches (union-find over the
// nodes, the reference as index n).
void check_connected(const Circuit& c, const std::string& where) {
  const int n = c.node_count();
  std::vector<int> parent(static_cast<std::size_t>(n + 1));
  for (int i = 0; i <= n; ++i) parent[static_cast<std::size_t>(i)] = i;
  auto find = [&](int i) {
    while (parent[static_cast<std::size_t>(i)] != i) {
      parent[static_cast<std::size_t>(i)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
      i = parent[static_cast<std::size_t>(i)];
    }
    return i;
  };
  auto idx = [n](int node) { return node < 0 ? n : node; };
  for (const auto& br : c.branches)
    parent[static_cast<std::size_t>(find(idx(br.from)))] = find(idx(br.to));
  for (int i = 0; i < n; ++i)
    if (find(i) != find(n))
      throw InputError(
          located(where, 0,
                  fmt::format("circuit node '{}' is floating: no path of branches joins it to the "
                              "reference node '{}'",
                              c.node_names[static_cast<std::size_t>(i)], c.reference_node)));
}

// The low-rank (Woodbury) pieces from G0 = the fixed branches' Laplacian (factorised in
// llt0): B has a column per rod (+1 at its branch's from node, -1 at its to node), b the
// fixed branches' coil and PM sources.
void set_lowrank_pieces(const Circuit& c, const Eigen::LLT<Eigen::MatrixXd>& llt0, int k,
                        CircuitMatrices& L) {
  const auto n = static_cast<Eigen::Index>(c.node_count());
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(n, k);
  Eigen::VectorXd b_coil = Eigen::VectorXd::Zero(n), b_pm = Eigen::VectorXd::Zero(n);
  for (int r = 0; r < k; ++r) {
    const auto& br =
        c.branches[static_cast<std::size_t>(c.rod_branch[static_cast<std::size_t>(r)])];
    if (br.from >= 0) B(br.from, r) += 1.0;
    if (br.to >= 0) B(br.to, r) -= 1.0;
  }
  for (const auto& br : c.branches) {
    if (br.rod >= 0) continue;
    const double g = 1.0 / br.fixed_reluctance_per_H;
    if (br.from >= 0) {
      b_coil(br.from) -= br.coil_turns * g;
      b_pm(br.from) -= br.pm_mmf_At * g;
    }
    if (br.to >= 0) {
      b_coil(br.to) += br.coil_turns * g;
      b_pm(br.to) += br.pm_mmf_At * g;
    }
  }
  L.W = llt0.solve(B);
  L.S = B.transpose() * L.W;
  L.psi_coil = llt0.solve(b_coil);
  L.psi_pm = llt0.solve(b_pm);
  L.Bt_psi_coil = B.transpose() * L.psi_coil;
  L.Bt_psi_pm = B.transpose() * L.psi_pm;
  for (int r = 0; r < k; ++r) {
    for (int q = 0; q < k; ++q) L.S8[static_cast<std::size_t>(8 * r + q)] = L.S(r, q);
    L.bt_coil8[static_cast<std::size_t>(r)] = L.Bt_psi_coil(r);
    L.bt_pm8[static_cast<std::size_t>(r)] = L.Bt_psi_pm(r);
  }
}

}  // namespace

CircuitLowRankView circuit_lowrank_view(const Circuit& c) {
  const CircuitMatrices& L = *c.matrices;
  return {L.S8.data(), L.bt_coil8.data(), L.bt_pm8.data()};
}

void finalize_circuit(Circuit& c, int rod_count, const std::string& where) {
  const int n = c.node_count();
  if (n == 0) throw InputError(located(where, 0, "circuit has no nodes besides the reference"));
  map_rod_branches(c, rod_count, where);
  check_connected(c, where);

  auto matrices = std::make_shared<CircuitMatrices>();
  auto& L = *matrices;
  L.fixed_laplacian = Eigen::MatrixXd::Zero(n, n);
  for (const auto& br : c.branches) {
    if (br.rod >= 0) continue;
    stamp_conductance(L.fixed_laplacian, br, 1.0 / br.fixed_reluctance_per_H);
  }
  c.matrices = matrices;
  // Low-rank pieces, when the fixed branches alone ground every node (G0 SPD).
  c.lowrank = Circuit::LowRank{};
  Eigen::LLT<Eigen::MatrixXd> llt0(L.fixed_laplacian);
  if (llt0.info() != Eigen::Success || rod_count == 0) return;
  set_lowrank_pieces(c, llt0, rod_count, L);
  c.lowrank.enabled = true;
}

void CircuitWorkspace::resize(const Circuit& c) {
  const int n = c.node_count();
  if (nodal.get() == nullptr) nodal.reset(std::make_unique<NodalBuffers>());
  NodalBuffers& nb = *nodal.get();
  nb.G = Eigen::MatrixXd::Zero(n, n);
  nb.rhs = Eigen::VectorXd::Zero(n);
  // Sized by a factorisation of the identity, not by LLT(n): LLT(n) leaves its status and
  // norm uninitialised, and copying such a workspace (a State copy) loads an indeterminate
  // enum (UBSan, issue 8). compute() sets both; step() refactorises in place, no allocation.
  nb.llt.compute(Eigen::MatrixXd::Identity(n, n));
  const int k = static_cast<int>(c.rod_branch.size());
  nb.z = SmallVector::Zero(k);
  reluctance.assign(c.branches.size(), 0.0);
  mmf.assign(c.branches.size(), 0.0);
  phi.assign(c.branches.size(), 0.0);
  rod_extra_mmf.assign(c.rod_branch.size(), 0.0);
}

namespace {

double branch_reluctance(const CircuitBranch& br, std::span<const double> rod_R) {
  return br.rod >= 0 ? rod_R[static_cast<std::size_t>(br.rod)] : br.fixed_reluctance_per_H;
}
double branch_mmf(const CircuitBranch& br, double current_A, double pm_scale,
                  const CircuitWorkspace& ws) {
  const double extra = br.rod >= 0 ? ws.rod_extra_mmf[static_cast<std::size_t>(br.rod)] : 0.0;
  return br.coil_turns * current_A + br.pm_mmf_At * pm_scale + extra;
}
// phi_b = (psi_from - psi_to + F) / R, with the potential drop psi_from - psi_to given.
void set_flux(const Circuit& c, std::size_t b, std::span<const double> rod_R, double current_A,
              double pm_scale, double drop, CircuitWorkspace& ws) {
  const auto& br = c.branches[b];
  ws.reluctance[b] = branch_reluctance(br, rod_R);
  ws.mmf[b] = branch_mmf(br, current_A, pm_scale, ws);
  ws.phi[b] = (drop + ws.mmf[b]) / ws.reluctance[b];
}
double potential_drop(const CircuitBranch& br, const Eigen::VectorXd& psi) {
  return (br.from >= 0 ? psi(br.from) : 0.0) - (br.to >= 0 ? psi(br.to) : 0.0);
}

// The k x k part of the low-rank solve (physics::rod_solve3, rod_solve_ldlt: written once over the
// number type in gmasim/physics/rod_circuit-inl.h, which the SIMD lanes also run). With D =
// diag(1/R_rod), F the rods' own MMFs and u = I psi_coil + pm psi_pm, the node potentials are
// psi = u - W z with z = D (B^T psi + F): z is the rod branches' fluxes phi_r = (drop_r + F_r) /
// R_r, and B^T psi = B^T u - S z gives (diag(R) + S) z = B^T u + F, one k x k solve for the rod
// fluxes themselves. Its matrices in fixed storage (CircuitMatrices: S row-major with stride 8).
struct FixedMatrices {
  const CircuitMatrices& L;
  double S(int a, int b) const { return L.S8[static_cast<std::size_t>(8 * a + b)]; }
  double bt_coil(int a) const { return L.bt_coil8[static_cast<std::size_t>(a)]; }
  double bt_pm(int a) const { return L.bt_pm8[static_cast<std::size_t>(a)]; }
};

// The rods' fluxes into ws.z (allocation-free); false where the solve fails (ws.z then holds
// what it reached: the caller reports the failure and reads none of it).
bool rod_solve(const CircuitMatrices& L, int k, const double* R, const double* mmf,
               double current_A, double pm_scale, NodalBuffers& ws) {
  const FixedMatrices M{L};
  double* z = ws.z.data();  // sized k by CircuitWorkspace::resize
  bool ok = false;
  switch (k) {
    case 1:
      ok = physics::rod_solve_ldlt<1>(M, k, R, mmf, current_A, pm_scale, z);
      break;
    case 2:
      ok = physics::rod_solve_ldlt<2>(M, k, R, mmf, current_A, pm_scale, z);
      break;
    case 3:
      ok = physics::rod_solve3(M, R, mmf, current_A, pm_scale, z);
      break;
    case 4:
      ok = physics::rod_solve_ldlt<4>(M, k, R, mmf, current_A, pm_scale, z);
      break;
    default:
      ok = physics::rod_solve_ldlt<0>(M, k, R, mmf, current_A, pm_scale, z);
  }
  return ok;
}

}  // namespace

bool solve_circuit(const Circuit& c, std::span<const double> rod_reluctance_per_H, double current_A,
                   double pm_scale, CircuitWorkspace& ws, bool all_branches) {
  if (!c.lowrank.enabled)
    return solve_circuit_full(c, rod_reluctance_per_H, current_A, pm_scale, ws);
  const CircuitMatrices& L = *c.matrices;
  NodalBuffers& nb = *ws.nodal.get();
  const int k = static_cast<int>(c.rod_branch.size());
  std::array<double, 8> mmf;  // written for r < k before it is read
  const double* R = rod_reluctance_per_H.data();
  for (int r = 0; r < k; ++r)
    mmf[static_cast<std::size_t>(r)] =
        branch_mmf(c.branches[static_cast<std::size_t>(c.rod_branch[static_cast<std::size_t>(r)])],
                   current_A, pm_scale, ws);
  const bool ok = rod_solve(L, k, R, mmf.data(), current_A, pm_scale, nb);
  if (!ok) return false;
  // The rod fluxes are the k x k solve's z (the same numbers whether or not the other branches
  // are wanted); the others from the node potentials.
  for (int r = 0; r < k; ++r) {
    const auto ur = static_cast<std::size_t>(r);
    const auto b = static_cast<std::size_t>(c.rod_branch[ur]);
    ws.reluctance[b] = R[r];
    ws.mmf[b] = mmf[ur];
    ws.phi[b] = nb.z(r);
  }
  if (!all_branches) return true;
  nb.rhs.noalias() = current_A * L.psi_coil + pm_scale * L.psi_pm;
  nb.rhs.noalias() -= L.W * nb.z;
  for (std::size_t b = 0; b < c.branches.size(); ++b)
    if (c.branches[b].rod < 0)
      set_flux(c, b, rod_reluctance_per_H, current_A, pm_scale,
               potential_drop(c.branches[b], nb.rhs), ws);
  return true;
}

bool solve_circuit_full(const Circuit& c, std::span<const double> rod_reluctance_per_H,
                        double current_A, double pm_scale, CircuitWorkspace& ws) {
  NodalBuffers& nb = *ws.nodal.get();
  nb.G = c.matrices->fixed_laplacian;
  nb.rhs.setZero();
  for (const auto& br : c.branches) {
    const double g = 1.0 / branch_reluctance(br, rod_reluctance_per_H);
    const double F = branch_mmf(br, current_A, pm_scale, ws);
    if (br.rod >= 0) stamp_conductance(nb.G, br, g);
    // phi_b = (psi_from - psi_to + F)/R; KCL at `from` (outflow) and `to` (inflow).
    if (br.from >= 0) nb.rhs(br.from) -= F * g;
    if (br.to >= 0) nb.rhs(br.to) += F * g;
  }
  nb.llt.compute(nb.G);
  if (nb.llt.info() != Eigen::Success) return false;
  nb.llt.solveInPlace(nb.rhs);  // rhs now holds psi
  for (std::size_t b = 0; b < c.branches.size(); ++b)
    set_flux(c, b, rod_reluctance_per_H, current_A, pm_scale, potential_drop(c.branches[b], nb.rhs),
             ws);
  return true;
}

}  // namespace gmasim
