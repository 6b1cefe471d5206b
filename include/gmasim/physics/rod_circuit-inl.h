// The rods' k x k system of the magnetic circuit's low-rank solve (src/circuit/netlist.cpp,
// solve_circuit; docs/model.md, "The magnetic circuit is a netlist"), written once over the number
// type T (issue 38, item 1): the scalar step's netlist solve and the SIMD lanes' kernel
// (src/lanes/step_kernel-inl.h) both run it. With u = I psi_coil + pm psi_pm the node potentials
// the coil and the magnets drive through the fixed branches and F the rods' own MMFs, the rods'
// fluxes z solve
//   (diag(R) + S) z = B^T u + F,   S = B^T G0^-1 B
// (no reciprocal of a rod's reluctance). The matrices come from an accessor Sx: T S(a, b),
// T bt_coil(a) = (B^T psi_coil)_a, T bt_pm(a) = (B^T psi_pm)_a, for rods a, b < k (per lane in the
// lanes: a batch may hold other circuits). Each returns where the solve holds: every pivot
// positive and every z finite (the scalar caller keeps z only there).
// No include guard: once per instance (laws.hpp's rule).

// Rod a's right-hand side, (B^T u + F)_a = I (B^T psi_coil)_a + pm (B^T psi_pm)_a + F_a.
template <class T, class Sx>
GMASIM_LAW_INLINE T rod_rhs(const Sx& L, int a, T I, T pm, T F) {
  return I * L.bt_coil(a) + pm * L.bt_pm(a) + F;
}

// finite: |x| at most the largest double (false for inf and NaN).
template <class T>
GMASIM_LAW_INLINE ::gmasim::physics::Mask<T> finite_value(T x) {
  return abs(x) <= 1.7976931348623157e308;
}

// Three rods (the built-in actuator), straight-line: A = S + diag(R) solved by its adjugate,
// z = adj(A) (B^T u + F) / det A, one division; the pivots of its L D L^T form are positive
// where Sylvester's criterion holds on the leading minors (a00, m2, det all > 0).
template <class T, class Sx>
GMASIM_LAW_INLINE ::gmasim::physics::Mask<T> rod_solve3(const Sx& L, const T* R, const T* mmf, T I,
                                                        T pm, T* z) {
  const T x0 = rod_rhs<T>(L, 0, I, pm, mmf[0]), x1 = rod_rhs<T>(L, 1, I, pm, mmf[1]);
  const T x2 = rod_rhs<T>(L, 2, I, pm, mmf[2]);
  // A = S + diag(R), its lower triangle (as the L D L^T form reads it).
  const T a00 = L.S(0, 0) + R[0], a10 = L.S(1, 0), a11 = L.S(1, 1) + R[1];
  const T a20 = L.S(2, 0), a21 = L.S(2, 1), a22 = L.S(2, 2) + R[2];
  const T c00 = a11 * a22 - a21 * a21, c01 = a20 * a21 - a10 * a22, c02 = a10 * a21 - a20 * a11;
  const T c11 = a00 * a22 - a20 * a20, c12 = a10 * a20 - a00 * a21, m2 = a00 * a11 - a10 * a10;
  const T det = a00 * c00 + a10 * c01 + a20 * c02;
  ::gmasim::physics::Mask<T> ok = a00 > 0.0 && m2 > 0.0 && det > 0.0;
  const T inv_det = 1.0 / det;
  z[0] = (c00 * x0 + c01 * x1 + c02 * x2) * inv_det;
  z[1] = (c01 * x0 + c11 * x1 + c12 * x2) * inv_det;
  z[2] = (c02 * x0 + c12 * x1 + m2 * x2) * inv_det;
  return ok && finite_value(z[0]) && finite_value(z[1]) && finite_value(z[2]);
}

// Any k <= 8 rods: diag(R) + S factorised as L D L^T without square roots (unit L below the
// diagonal), one division per pivot, then the two triangular solves. K > 0 fixes k at compile time
// (the loops unrolled); K = 0 takes k_any.
template <int K, class T, class Sx>
GMASIM_LAW_INLINE ::gmasim::physics::Mask<T> rod_solve_ldlt(const Sx& L, int k_any, const T* R,
                                                            const T* mmf, T I, T pm, T* z) {
  const int k = K > 0 ? K : k_any;
  T A[8][8], piv[8], inv_piv[8];  // written before read (no fill: hot path)
  ::gmasim::physics::Mask<T> ok = true_mask(I);
  for (int r = 0; r < k; ++r) z[r] = rod_rhs<T>(L, r, I, pm, mmf[r]);
  for (int j = 0; j < k; ++j) {
    T d = L.S(j, j) + R[j];
    for (int p = 0; p < j; ++p) d = d - A[j][p] * A[j][p] * piv[p];
    ok = ok && d > 0.0;
    piv[j] = d;
    inv_piv[j] = 1.0 / d;
    for (int i = j + 1; i < k; ++i) {
      T a = L.S(i, j);
      for (int p = 0; p < j; ++p) a = a - A[i][p] * A[j][p] * piv[p];
      A[i][j] = a * inv_piv[j];
    }
  }
  for (int i = 0; i < k; ++i)
    for (int p = 0; p < i; ++p) z[i] = z[i] - A[i][p] * z[p];
  for (int i = k - 1; i >= 0; --i) {
    z[i] = z[i] * inv_piv[i];
    for (int p = i + 1; p < k; ++p) z[i] = z[i] - A[p][i] * z[p];
  }
  for (int r = 0; r < k; ++r) ok = ok && finite_value(z[r]);
  return ok;
}
