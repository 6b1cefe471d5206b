// The step's mechanical stages, written once over the number type T (issue 38, item 1;
// docs/model.md, "The step"): each rod's strain, force and stiffness at its new magnetisation
// (stage 2: eq. 11-14, 17), its load stiffness and oscillator over the step (stage 3: eq.
// 15-18), and the sensor mount's probe. Instantiated for double (the scalar step,
// src/model/step.cpp, through gmasim/physics/stages.hpp) and per SIMD target for the lanes
// (src/lanes/step_lanes.cpp); each instance gives only data through a context (Ctx) c:
//   int rods()
//   RodStrainT<T> strain_state(i), void store_strain(i, const RodStrainT<T>&)
//   RodOscillatorT<T> oscillator(i), void store_oscillator(i, const RodOscillatorT<T>&)
//   T x(i)                                    the rod's state, as each stage needs it
//   T M(i)                                    its magnetisation (after the magnetic stage)
//   RodMechanicsInputsT<T> inputs(i)          the rod's constants of eq. 11-14, 17
//   T lambda_s()                              the material's saturation magnetostriction
//   T fixed_compliance(i); const int* chain(i); int chain_count(i)    its load chain (eq. 18)
//   T mass_osc(i), inv_mass_osc(i), damping_osc(i)                    its oscillator (eq. 15)
//   void check_x(i, T x)                      |x| <= 1 m (a DivergenceError, or the lane's record)
// and, for the sensor mount (sensor_mount_stage):
//   bool mount(), bool mount_on_output()      whether it is there, and its base (the output, or
//                                             the housing's recoil)
//   T momentum_mass(i), actuator_mass()       the recoil's p = sum (m/2 + m_lr) x over M
//   T mount_mass(), mount_inv_mass(), mount_damping(), mount_stiffness()
//   MountStateT<T> mount_state(), void store_mount(const MountStateT<T>&), void check_z(T z)
// No include guard: once per instance (laws.hpp's rule); after laws-inl.h, whose laws it calls.

// A rod's mechanical state (RodState's; the lanes' kF, kKRod, ...) as stage 2 reads and writes
// it: force F [N], its stiffness k_rod and its load's k_load [N/m], the modulus E [Pa], the
// strain, and the prestress law's cache.
template <class T>
struct RodStrainT {
  T F, k_rod, k_load, E, lambda;
  ExpPointT<T> prestress;
};
// ... and as stage 3 does: F, k_rod and k_load, the oscillator's K [N/m], the displacement x [m]
// and velocity v [m/s], and the oscillator's decay cache.
template <class T>
struct RodOscillatorT {
  T F, k_rod, k_load, K_osc, x, v;
  ExpPointT<T> osc_decay;
};

// The constants of rod_mechanics (eq. 11-14, 17; RodConditions').
template <class T>
struct RodMechanicsInputsT {
  T inv_MsT_E;
  DeltaETermsT<T> dE;
  T inv_Ms_strain, sigma_p_Pa, four_sp_over_ls, area_m2, area_over_length_m, length_over_area_per_m,
      joint_compliance_m_per_N;
};

// The sensor mount's state: the probe's z [m] and z' [m/s], its base q [m], the decay cache.
template <class T>
struct MountStateT {
  T z, zv, q;
  ExpPointT<T> decay;
};

// Stage 2: each rod's Delta-E modulus (eq. 13), magnetostriction (eq. 11-12), force (eq. 14) and
// stiffness (eq. 17) at its new magnetisation. Keeps the start's force F0 and stiffness K0 =
// k_rod + k_load (eq. 16) and the end's compliance 1/k_rod for stage 3.
template <class T, class Ctx>
GMASIM_LAW_INLINE void strain_stage(Ctx& c, T* F0, T* K0, T* compliance) {
  for (int i = 0; i < c.rods(); ++i) {
    RodStrainT<T> r = c.strain_state(i);
    F0[i] = r.F;
    K0[i] = r.k_rod + r.k_load;
    const RodMechanicsInputsT<T> p = c.inputs(i);
    const RodMechanicsT<T> k =
        rod_mechanics<T>(c.M(i), p.inv_MsT_E, p.dE, p.inv_Ms_strain, c.lambda_s(), p.sigma_p_Pa,
                         p.four_sp_over_ls, p.area_m2, p.area_over_length_m,
                         p.length_over_area_per_m, p.joint_compliance_m_per_N, r.prestress);
    r.E = k.E_Pa;
    r.lambda = k.lambda;
    r.F = k.F_N;
    r.k_rod = k.k_rod_N_per_m;
    compliance[i] = k.compliance_m_per_N;
    c.store_strain(i, r);
  }
}

// Stage 3: each rod's oscillator, exact over the step with the force linear from F0 to F1 and
// the stiffness of eq. (16) at mid-step (the mean of its values at the ends, where the end's
// load stiffness of eq. (18) needs every rod's new compliance: stage 2). Guard: |x| <= 1 m.
template <class T, class Ctx>
GMASIM_LAW_INLINE void oscillators_stage(Ctx& c, const T* F0, const T* K0, const T* compliance,
                                         T h) {
  for (int i = 0; i < c.rods(); ++i) {
    RodOscillatorT<T> r = c.oscillator(i);
    r.k_load = chain_stiffness<T>(c.fixed_compliance(i), compliance, c.chain(i), c.chain_count(i));
    r.K_osc = mid_step_stiffness<T>(K0[i], r.k_rod, r.k_load);
    oscillator_step<T>(c.mass_osc(i), c.inv_mass_osc(i), c.damping_osc(i), r.K_osc, F0[i], r.F, h,
                       r.x, r.v, r.osc_decay);
    c.store_oscillator(i, r);
    c.check_x(i, r.x);
  }
}

// Eq. (20): the stack's displacement, the sum of the rods' x.
template <class T, class Ctx>
GMASIM_LAW_INLINE T stack_displacement(const Ctx& c) {
  T y = 0.0;
  for (int i = 0; i < c.rods(); ++i) y = y + c.x(i);
  return y;
}

// The sensor mount's base (options.sensor_mount_base): the output y_stack, or the housing's
// recoil q = p / M with p = sum (m/2 + m_lr) x (model.hpp, SensorMountModel).
template <class T, class Ctx>
GMASIM_LAW_INLINE T mount_base(const Ctx& c, T y_stack) {
  if (c.mount_on_output()) return y_stack;
  T p = 0.0;
  for (int i = 0; i < c.rods(); ++i) p = p + c.momentum_mass(i) * c.x(i);
  return p / c.actuator_mass();
}

// The probe on its bracket over the step (model.hpp, SensorMountModel): with w = u - q,
// m w'' + c w' + k w = -(c q' + k q), so z = q - u solves m z'' + c (z' - q') + k (z - q) = 0
// with q linear over the step: linear forcing, and base_excited_step is exact. Guard: |z| <= 1 m.
template <class T, class Ctx>
GMASIM_LAW_INLINE void sensor_mount_stage(Ctx& c, T y_stack, T h) {
  if (!c.mount()) return;
  MountStateT<T> s = c.mount_state();
  const T q1 = mount_base<T>(c, y_stack);
  base_excited_step<T>(c.mount_mass(), c.mount_inv_mass(), c.mount_damping(), c.mount_stiffness(),
                       s.q, q1, h, s.z, s.zv, s.decay);
  s.q = q1;
  c.store_mount(s);
  c.check_z(s.z);
}
