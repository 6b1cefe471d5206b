// The order of the step's stages (docs/model.md, "The step"), written once (issue 38, item 1):
// the scalar step (src/model/step.cpp, step_law, with ScalarStages of
// gmasim/model/step_stages.hpp), the SIMD lanes' kernel (src/lanes/step_lanes.cpp, LaneStages)
// and the tests (tests/test_stages.cpp) run this one function with their stages.
//   begin       stage 0: the step's end time and start current (the ledgers' start values)
//   magnetic    stage 1: circuit, eddy field and the magnetisation law; guards on H and M
//   strain      stage 2: Delta-E modulus, magnetostriction, force, stiffness (eq. 11-14, 17)
//   mechanics   stage 3: the rods' oscillators (eq. 15-18) and the sensor mount
//   end_time    the state's time and current become the step's end's
//   outputs     stage 4: y (eq. 20-21) and the flux densities
//   ledger      stage 5: the energy ledgers, when enabled
// No include guard: once per instance (laws.hpp's rule).
template <class Stages>
GMASIM_LAW_INLINE void run_stages(Stages& st) {
  st.begin();
  st.magnetic();
  st.strain();
  st.mechanics();
  st.end_time();
  st.outputs();
  st.ledger();
}
