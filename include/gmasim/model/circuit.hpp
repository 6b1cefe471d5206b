// The magnetic equivalent circuit as a netlist (eq. 23 is one instance of it).
//
// A branch b runs from node `from` to node `to`; its flux phi_b counts positive from
// `from` to `to`. It has a reluctance R_b [1/H] and an MMF source F_b [A-turns] that
// drives flux from `from` to `to`:
//     phi_b = (psi_from - psi_to + F_b) / R_b
// where psi are magnetic scalar potentials [A-turns], zero at the reference node.
// Flux conservation at every non-reference node gives the nodal (graph-Laplacian) system
//     sum_b A_nb phi_b = 0   =>   (A R^-1 A^T) psi = -A R^-1 F
// Node index -1 is the reference node.
//
// Only the rod branches change from step to step (their reluctance follows M through
// eq. 2-3). When the fixed branches alone already tie every node to the reference (true
// of the MDMA), the Laplacian is G = G0 + B D B^T with G0 constant, B the incidence of the
// k rod branches and D = diag(1/R_rod). The Woodbury identity then reduces each step to a
// k x k solve with matrices precomputed once (Circuit::lowrank); otherwise the full n x n system is
// factorised every step. Both give the same fluxes (tested).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace gmasim {

struct CircuitBranch {
  std::string name;
  int from = -1;                        // node index, -1 = reference
  int to = -1;                          // node index, -1 = reference
  double fixed_reluctance_per_H = 0.0;  // used when rod < 0
  int rod = -1;                         // index of the rod whose reluctance (eq. 2) this branch is
  double coil_turns = 0.0;              // MMF contribution N * I [A-turns per A]
  double pm_mmf_At = 0.0;  // permanent-magnet MMF F_pm at T0 [A-turns], scaled by eq. (1)
};

// The Eigen matrices of the nodal solve are private to src/circuit/netlist.cpp:
// CircuitMatrices (the fixed part of the Laplacian and the precomputed pieces of the low-rank
// solve, set by finalize_circuit) and NodalBuffers (a workspace's nodal matrix, its Cholesky
// factorisation and the node potentials).
struct CircuitMatrices;
struct NodalBuffers;

struct Circuit {
  std::vector<std::string> node_names;  // non-reference nodes, index = position
  std::string reference_node;
  std::vector<CircuitBranch> branches;
  std::vector<int> rod_branch;  // rod index -> branch index
  // Set by finalize_circuit: enabled when the fixed branches alone ground every node, so each
  // solve takes the k x k low-rank (Woodbury) path.
  struct LowRank {
    bool enabled = false;
  } lowrank;
  std::shared_ptr<const CircuitMatrices> matrices;  // set by finalize_circuit, then immutable

  int node_count() const { return static_cast<int>(node_names.size()); }
  int branch_count() const { return static_cast<int>(branches.size()); }
};

// Builds the index structure, checks it (unknown nodes, floating nodes, rod branches)
// and precomputes the fixed part of the Laplacian. Throws InputError with `where` in
// the message.
void finalize_circuit(Circuit& c, int rod_count, const std::string& where);

// The low-rank (Woodbury) pieces finalize_circuit precomputed, for a circuit on the low-rank
// path (c.lowrank.enabled; k = the rod count <= 8): with G0 the fixed branches' Laplacian and B
// the rod branches' incidence, S = B^T G0^-1 B (row-major, row stride 8) and B^T G0^-1 b for
// the coil (per ampere) and the magnets (per unit scale). The views live as long as c. Used by
// the SIMD lanes (src/lanes/pack.cpp), which copy them into every lane.
struct CircuitLowRankView {
  const double* S8;        // S(r, q) = S8[8 r + q]
  const double* bt_coil8;  // B^T G0^-1 b_coil, per rod
  const double* bt_pm8;    // B^T G0^-1 b_pm, per rod
};
CircuitLowRankView circuit_lowrank_view(const Circuit& c);

// Owns a workspace's NodalBuffers and copies them with it, so that a State stays a copyable
// value. Defined in src/circuit/netlist.cpp.
class NodalBuffersPtr {
 public:
  NodalBuffersPtr();
  ~NodalBuffersPtr();
  NodalBuffersPtr(const NodalBuffersPtr& other);
  NodalBuffersPtr& operator=(const NodalBuffersPtr& other);
  NodalBuffersPtr(NodalBuffersPtr&& other) noexcept;
  NodalBuffersPtr& operator=(NodalBuffersPtr&& other) noexcept;
  NodalBuffers* get() const { return p_.get(); }
  void reset(std::unique_ptr<NodalBuffers> p);

 private:
  std::unique_ptr<NodalBuffers> p_;
};

// Buffers of the nodal solve, sized once.
struct CircuitWorkspace {
  NodalBuffersPtr nodal;           // nodal matrix, factorisation, potentials (netlist.cpp)
  std::vector<double> reluctance;  // per branch, this step [1/H]
  std::vector<double> mmf;         // per branch, this step [A-turns]
  std::vector<double> phi;         // per branch, solved flux [Wb]
  // Per rod: an MMF added to the rod branch's own source [A-turns], zero unless the caller
  // sets it (the consistent magnetic state's linearised rods, model/step.cpp).
  std::vector<double> rod_extra_mmf;

  void resize(const Circuit& c);
};

// Solves the circuit for the given rod reluctances, coil current and PM MMF (already
// temperature-scaled by eq. 1). Fills ws.phi for every branch, or for the rod branches
// only when all_branches is false (the step needs no more). Allocation-free once ws is
// sized. Returns false if the nodal matrix is not positive definite.
bool solve_circuit(const Circuit& c, std::span<const double> rod_reluctance_per_H, double current_A,
                   double pm_scale, CircuitWorkspace& ws, bool all_branches = true);
// The same solve, always by factorising the full nodal matrix (reference for tests).
bool solve_circuit_full(const Circuit& c, std::span<const double> rod_reluctance_per_H,
                        double current_A, double pm_scale, CircuitWorkspace& ws);

}  // namespace gmasim
