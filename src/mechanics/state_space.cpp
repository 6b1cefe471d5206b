// The linearised plant as a state space (gmasim/mechanics/state_space.hpp).
#include "gmasim/mechanics/state_space.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/physics/magnetic.hpp"
#include "mechanics/dense.hpp"

namespace gmasim {
namespace {

using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using cd = std::complex<double>;

struct Builder {
  const Model& m;
  const SmallSignalModel& L;
  StateSpace ss;
  Matrix A, B, C;
  std::size_t n = 0;

  std::size_t H(std::size_t i) const { return i; }
  std::size_t X(std::size_t i) const { return n + i; }
  std::size_t V(std::size_t i) const { return 2 * n + i; }

  // The magnetic rows: the consistent reading's port equations
  //   K dH' = b dI - P dH,  P_ij = S_ij A_j mu0 (1 + chi_j) + delta_ij l_i,
  //   K_ii = l_i kappa_i mu0 (1 + chi_i)   (eq. 7's H_c - H = kappa dB/dt, dB = mu0 (1 + chi) dH);
  // or the printed reading's lagged static field tau_i dHl_i' = g_i dI + sum_j G_ij chi_j dHl_j -
  // dHl_i (eq. 7's first-order lag of the circuit's field).
  void magnetic() {
    for (std::size_t i = 0; i < n; ++i) {
      const std::string& name = m.rods[i].name;
      if (L.consistent) {
        const double K = L.length_m[i] * L.kappa_s_m_per_H[i] * physics::kMu0 * (1.0 + L.chi[i]);
        if (!(K > 0.0))
          throw InputError(
              fmt::format("linearize: rod '{}' has no eddy lag (kappa = {} s m/H): "
                          "its field is algebraic, not a state",
                          name, L.kappa_s_m_per_H[i]));
        for (std::size_t j = 0; j < n; ++j) {
          double P = L.port_S_per_H[i * n + j] * L.area_m2[j] * physics::kMu0 * (1.0 + L.chi[j]);
          if (i == j) P += L.length_m[i];
          A(H(i), H(j)) = -P / K;
        }
        B(H(i), 0) = L.port_b_At_per_A[i] / K;
      } else {
        const double tau = L.tau_s[i];
        if (!(tau > 0.0))
          throw InputError(fmt::format(
              "linearize: rod '{}' has no eddy lag (tau = {} s): its field is algebraic", name,
              tau));
        for (std::size_t j = 0; j < n; ++j)
          A(H(i), H(j)) = (L.G[i * n + j] * L.chi[j] - (i == j ? 1.0 : 0.0)) / tau;
        B(H(i), 0) = L.g_A_per_m_per_A[i] / tau;
      }
      ss.states.push_back(name + "_H");
      ss.state_units.push_back("A/m");
    }
  }

  // Eq. (15) per rod: x' = v, m v' = sum_j D_ij chi_j dH_j - c v - K x.
  void mechanics() {
    for (std::size_t i = 0; i < n; ++i) {
      A(X(i), V(i)) = 1.0;
      const double mass = L.mass_kg[i];
      for (std::size_t j = 0; j < n; ++j)
        A(V(i), H(j)) = L.D_N_per_A_per_m[i * n + j] * L.chi[j] / mass;
      A(V(i), X(i)) = -L.stiffness_N_per_m[i] / mass;
      A(V(i), V(i)) = -L.damping_N_s_per_m[i] / mass;
    }
    for (std::size_t i = 0; i < n; ++i) {
      ss.states.push_back(m.rods[i].name + "_x");
      ss.state_units.push_back("m");
    }
    for (std::size_t i = 0; i < n; ++i) {
      ss.states.push_back(m.rods[i].name + "_v");
      ss.state_units.push_back("m/s");
    }
  }

  // The sensor's reading (eq. 20 through the sensor mount, model.hpp SensorMountModel). Recoil:
  // the probe's deflection u = Q m s^2/(m s^2 + c s + k), Q = sum r_i x_i, as e = u - Q with
  // m e'' + c e' + k e = -c Q' - k Q, and y = sum x_i - Q - e. Output: the probe z with
  // m z'' + c z' + k z = c Y' + k Y, y = z.
  void sensor() {
    for (std::size_t i = 0; i < n; ++i) C(0, X(i)) = 1.0;
    if (!L.sensor_mount) return;
    const std::size_t e = 3 * n, ed = 3 * n + 1;
    const double mass = L.sm_mass_kg, c = L.sm_damping_N_s_per_m, k = L.sm_stiffness_N_per_m;
    A(e, ed) = 1.0;
    A(ed, e) = -k / mass;
    A(ed, ed) = -c / mass;
    for (std::size_t i = 0; i < n; ++i) {
      const double drive = L.sm_on_output ? 1.0 : -L.recoil_per_x[i];
      A(ed, X(i)) = k * drive / mass;
      A(ed, V(i)) = c * drive / mass;
    }
    if (L.sm_on_output) {
      C.row(0).setZero();
      C(0, e) = 1.0;
      ss.states.insert(ss.states.end(), {"probe_z", "probe_z_dot"});
    } else {
      for (std::size_t i = 0; i < n; ++i) C(0, X(i)) = 1.0 - L.recoil_per_x[i];
      C(0, e) = -1.0;
      ss.states.insert(ss.states.end(), {"probe_e", "probe_e_dot"});
    }
    ss.state_units.insert(ss.state_units.end(), {"m", "m/s"});
  }

  // The induction coil's flux density (consistent reading): its rods' flux A mu0 (1 + chi) dH over
  // their area.
  void flux_density() {
    double area = 0.0;
    for (int b : m.flux_sensor_branches) {
      const auto rod =
          static_cast<std::size_t>(m.circuit.branches[static_cast<std::size_t>(b)].rod);
      area += L.area_m2[rod];
      C(1, H(rod)) += L.area_m2[rod] * physics::kMu0 * (1.0 + L.chi[rod]);
    }
    C.row(1) /= area;
  }

  StateSpace build() {
    n = static_cast<std::size_t>(L.n);
    const std::size_t ns = 3 * n + (L.sensor_mount ? 2 : 0);
    const std::size_t no = L.consistent ? 2 : 1;
    A = Matrix::Zero(static_cast<Eigen::Index>(ns), static_cast<Eigen::Index>(ns));
    B = Matrix::Zero(static_cast<Eigen::Index>(ns), 1);
    C = Matrix::Zero(static_cast<Eigen::Index>(no), static_cast<Eigen::Index>(ns));
    ss.temperature_C = L.temperature_C;
    ss.bias_A = L.bias_A;
    ss.magnetic_state = L.consistent
                            ? "dH [A/m]: the rods' fields, eq. (7)'s eddy lag in the port equations"
                            : "dH_l [A/m]: the rods' lagged static fields, eq. (7) (printed)";
    magnetic();
    mechanics();
    sensor();
    ss.outputs = {"y"};
    ss.output_units = {"m"};
    if (L.consistent) {
      flux_density();
      ss.outputs.push_back("B");
      ss.output_units.push_back("T");
    }
    ss.n_states = static_cast<int>(ns);
    ss.n_outputs = static_cast<int>(no);
    ss.A.assign(A.data(), A.data() + A.size());
    ss.B.assign(B.data(), B.data() + B.size());
    ss.C.assign(C.data(), C.data() + C.size());
    ss.D.assign(no, 0.0);
    return ss;
  }
};

// The stack's block: the full plant's rods' states (the mount's states never feed back into
// them), with the outputs y_stack = sum x, the mount's base q, and B when the plant has it.
StateSpace stack_block(const StateSpace& full, const SmallSignalModel& L) {
  const std::size_t n = static_cast<std::size_t>(L.n), ns = 3 * n;
  const std::size_t nf = static_cast<std::size_t>(full.n_states);
  StateSpace b;
  b.temperature_C = full.temperature_C;
  b.bias_A = full.bias_A;
  b.magnetic_state = full.magnetic_state;
  b.n_states = static_cast<int>(ns);
  b.states.assign(full.states.begin(), full.states.begin() + static_cast<std::ptrdiff_t>(ns));
  b.state_units.assign(full.state_units.begin(),
                       full.state_units.begin() + static_cast<std::ptrdiff_t>(ns));
  for (std::size_t i = 0; i < ns; ++i) {
    for (std::size_t j = 0; j < ns; ++j) b.A.push_back(full.A[i * nf + j]);
    b.B.push_back(full.B[i]);
  }
  b.outputs = {"y_stack", "q"};
  b.output_units = {"m", "m"};
  std::vector<double> y(ns, 0.0), q(ns, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    y[n + i] = 1.0;
    q[n + i] = L.sensor_mount && !L.sm_on_output ? L.recoil_per_x[i] : 1.0;
  }
  b.C = y;
  b.C.insert(b.C.end(), q.begin(), q.end());
  if (full.n_outputs > 1) {  // B: its row of C over the rods' states
    b.outputs.push_back(full.outputs[1]);
    b.output_units.push_back(full.output_units[1]);
    for (std::size_t j = 0; j < ns; ++j) b.C.push_back(full.C[nf + j]);
  }
  b.n_outputs = static_cast<int>(b.outputs.size());
  b.D.assign(b.outputs.size(), 0.0);
  b.input = full.input;
  b.input_unit = full.input_unit;
  return b;
}

// The mount's block: the bracket base-excited by q, z = q (c s + k)/(m s^2 + c s + k), in observer
// form (z and zeta = z' + (c/m)(z - q) as states, q as the input without its derivative):
//   z' = -(c/m) z + zeta + (c/m) q,  zeta' = -(k/m) z + (k/m) q;  dy = z - q (recoil) or z.
StateSpace mount_block(const StateSpace& full, const SmallSignalModel& L) {
  const double cm = L.sm_damping_N_s_per_m / L.sm_mass_kg,
               km = L.sm_stiffness_N_per_m / L.sm_mass_kg;
  StateSpace b;
  b.temperature_C = full.temperature_C;
  b.bias_A = full.bias_A;
  b.n_states = 2;
  b.n_outputs = 1;
  b.A = {-cm, 1.0, -km, 0.0};
  b.B = {cm, km};
  b.C = {1.0, 0.0};
  b.D = {L.sm_on_output ? 0.0 : -1.0};
  b.states = {"probe_z", "probe_zeta"};
  b.state_units = {"m", "m/s"};
  b.outputs = {"dy"};
  b.output_units = {"m"};
  b.input = "q";
  b.input_unit = "m";
  b.magnetic_state = "none (the sensor mount's bracket)";
  return b;
}

Eigen::Map<const Matrix> view(const std::vector<double>& v, int rows, int cols) {
  return {v.data(), rows, cols};
}

// A diagonal similarity x = T x~ with powers of two (exact in floating point) that brings each
// state's row and column of A to comparable norms (Parlett and Reinsch's balancing, as LAPACK's
// dgebal): the SI states span A/m to m, so A's entries span twenty decades. Applied to A, B
// and C it leaves the transfer function, the poles and the zeros as they are, and lets the
// eigenvalue solvers resolve them.
struct Balanced {
  Eigen::MatrixXd A, B, C;
};
Balanced balanced(const StateSpace& ss) {
  const int n = ss.n_states;
  Balanced b{view(ss.A, n, n), view(ss.B, n, 1), view(ss.C, ss.n_outputs, n)};
  for (int sweep = 0; sweep < 50; ++sweep) {
    bool changed = false;
    for (int i = 0; i < n; ++i) {
      const double c = b.A.col(i).cwiseAbs().sum() - std::abs(b.A(i, i));
      const double r = b.A.row(i).cwiseAbs().sum() - std::abs(b.A(i, i));
      if (!(c > 0.0) || !(r > 0.0)) continue;
      const double f = std::exp2(std::round(0.5 * std::log2(r / c)));
      if (f == 1.0) continue;
      b.A.col(i) *= f;
      b.A.row(i) /= f;
      b.B.row(i) /= f;
      b.C.col(i) *= f;
      changed = true;
    }
    if (!changed) break;
  }
  return b;
}

bool by_imag_then_real(const cd& a, const cd& b) {
  return a.imag() != b.imag() ? a.imag() < b.imag() : a.real() < b.real();
}

}  // namespace

StateSpace state_space_whole(const Model& m, const SmallSignalModel& L);

StateSpace state_space(const Model& m, const SmallSignalModel& L) {
  StateSpace ss = state_space_whole(m, L);
  ss.blocks.push_back(stack_block(ss, L));
  if (L.sensor_mount) ss.blocks.push_back(mount_block(ss, L));
  ss.interconnection = !L.sensor_mount  ? "y = y_stack"
                       : L.sm_on_output ? "y = dy"
                                        : "y = y_stack + dy";
  return ss;
}

std::complex<double> StateSpace::blocks_response(double f_Hz) const {
  if (blocks.empty()) throw InputError("blocks_response: this state space has no blocks");
  const std::complex<double> y_stack = blocks[0].response(f_Hz, 0);
  if (blocks.size() < 2) return y_stack;
  const std::complex<double> dy = blocks[1].response(f_Hz, 0) * blocks[0].response(f_Hz, 1);
  return interconnection == "y = dy" ? dy : y_stack + dy;
}

StateSpace state_space_whole(const Model& m, const SmallSignalModel& L) {
  return Builder{m, L, {}, {}, {}, {}, 0}.build();
}

std::complex<double> StateSpace::response(double f_Hz, int out) const {
  const int n = n_states;
  const cd s(0.0, 2.0 * M_PI * f_Hz);
  const Eigen::MatrixXcd M = s * Eigen::MatrixXcd::Identity(n, n) - view(A, n, n).cast<cd>();
  const Eigen::VectorXcd x = M.partialPivLu().solve(view(B, n, 1).cast<cd>());
  return (view(C, n_outputs, n).row(out).cast<cd>() * x)(0) + D[static_cast<std::size_t>(out)];
}

double StateSpace::dc_gain(int out) const {
  const int n = n_states;
  const Eigen::VectorXd x = view(A, n, n).partialPivLu().solve(view(B, n, 1).col(0));
  return -(view(C, n_outputs, n).row(out) * x)(0) + D[static_cast<std::size_t>(out)];
}

std::vector<std::complex<double>> StateSpace::poles() const {
  std::vector<cd> p = dense::eigenvalues(balanced(*this).A);
  std::sort(p.begin(), p.end(), by_imag_then_real);
  return p;
}

// The zeros of output `out` are the finite eigenvalues z of the pencil (M, N) = ([A B; C D],
// [I 0; 0 0]) (the Rosenbrock system matrix loses rank at z). Shift and invert turn it into a
// standard eigenproblem, so no generalized (QZ) solver is needed: (M - z N) v = 0 if and only if
// (M - sigma N)^-1 N v = v / (z - sigma), so each eigenvalue mu != 0 gives z = sigma + 1 / mu
// (Saad, Numerical Methods for Large Eigenvalue Problems, 2nd ed., sec. 8.2). The pencil's
// infinite eigenvalues give mu ~ 0, i.e. z at a huge magnitude: a zero is listed when finite and
// within 1000 times the fastest pole's magnitude (on the built-in plant the spurious ones land
// near 4e9 1/s, the zeros within 1e5 1/s). sigma = -0.1 x the fastest pole's magnitude, or
// another multiple if that makes M - sigma N singular.
std::vector<std::complex<double>> StateSpace::zeros(int out) const {
  const int n = n_states;
  const Balanced b = balanced(*this);
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1), N = Eigen::MatrixXd::Zero(n + 1, n + 1);
  M.topLeftCorner(n, n) = b.A;
  M.topRightCorner(n, 1) = b.B;
  M.bottomLeftCorner(1, n) = b.C.row(out);
  M(n, n) = D[static_cast<std::size_t>(out)];
  N.topLeftCorner(n, n).setIdentity();
  double reach = 1.0;
  for (const cd& p : poles()) reach = std::max(reach, std::abs(p));
  for (const double shift : {0.1, 0.37, 0.013}) {
    const double sigma = -shift * reach;
    const Eigen::MatrixXd S = (M - sigma * N).partialPivLu().solve(N);
    if (!S.allFinite()) continue;
    std::vector<cd> z;
    for (const cd& mu : dense::eigenvalues(S)) {
      const cd zk = sigma + 1.0 / mu;
      if (std::isfinite(zk.real()) && std::isfinite(zk.imag()) && std::abs(zk) <= 1e3 * reach)
        z.push_back(zk);
    }
    std::sort(z.begin(), z.end(), by_imag_then_real);
    return z;
  }
  return {};  // unreachable for a pencil with finitely many zeros
}

}  // namespace gmasim
