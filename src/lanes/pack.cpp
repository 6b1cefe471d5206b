// LaneBatch (gmasim/lanes.hpp): packing models, conditions and states into the lanes'
// structure of arrays (lanes/lane_data.hpp), unpacking, and each lane's diagnosis.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "gmasim/errors.hpp"
#include "gmasim/magnetisation/laws.hpp"
#include "gmasim/model/validity.hpp"
#include "gmasim/simulate/lanes.hpp"
#include "lanes/lane_data.hpp"

namespace gmasim {

using lanes::LaneData;

bool lanes_supported(const Model& m, std::string* why) {
  auto no = [&](const char* reason) {
    if (why) *why = reason;
    return false;
  };
  if (!with_magnetisation_law(m.options.magnetisation_law,
                              [](auto law) { return decltype(law)::has_lanes; }))
    return no("the model's magnetisation law has no lane kernel");
  if (m.options.magnetic_state != MagneticState::Consistent)
    return no("the lanes run the consistent magnetic state only");
  if (!m.circuit.lowrank.enabled) return no("the circuit is not on the low-rank path");
  if (m.rods.empty() || m.rods.size() > static_cast<std::size_t>(lanes::kMaxRods))
    return no("the lanes take 1 to 8 rods");
  for (int b : m.flux_sensor_branches)
    if (m.circuit.branches[static_cast<std::size_t>(b)].rod < 0)
      return no("the flux sensor reads a branch that is not a rod's");
  return true;
}

std::string lanes_target() { return lanes::dispatch_target_name(); }
int lanes_width() { return lanes::dispatch_lanes(); }

namespace {

lanes::Structure structure_of(const Model& m, const Conditions& c) {
  lanes::Structure st;
  st.rods = m.rod_count();
  st.preisach = m.options.magnetisation_law == MagnetisationLaw::Preisach;
  st.mount = m.sensor_mount.enabled;
  st.mount_on_output = m.options.sensor_mount_base == SensorMountBase::Output;
  st.xT_in_output = m.options.thermal_expansion_in_output;
  for (int b : m.flux_sensor_branches)
    st.sensor_rods[static_cast<std::size_t>(st.sensor_count++)] =
        m.circuit.branches[static_cast<std::size_t>(b)].rod;
  for (std::size_t i = 0; i < c.rods.size(); ++i) {
    st.chain_count[i] = c.rods[i].chain_rod_count;
    for (int k = 0; k < c.rods[i].chain_rod_count; ++k)
      st.chain[i][static_cast<std::size_t>(k)] = c.rods[i].chain_rods[static_cast<std::size_t>(k)];
  }
  return st;
}

bool same_structure(const lanes::Structure& a, const lanes::Structure& b) {
  return a.rods == b.rods && a.preisach == b.preisach && a.mount == b.mount &&
         a.xT_in_output == b.xT_in_output && a.mount_on_output == b.mount_on_output &&
         a.sensor_count == b.sensor_count && a.sensor_rods == b.sensor_rods && a.chain == b.chain &&
         a.chain_count == b.chain_count;
}

// Lane j's State scalars and constants (the GlobalField numbers), its failure record cleared.
void pack_globals(LaneData& L, std::size_t j, const Model& m, const Conditions& c, const State& s) {
  using namespace lanes;
  double sensor_area = 0.0;
  for (int b : m.flux_sensor_branches)
    sensor_area +=
        c.rods[static_cast<std::size_t>(m.circuit.branches[static_cast<std::size_t>(b)].rod)]
            .area_m2;
  auto glob = [&](int f) -> double& { return L.glob(f)[j]; };
#define GMASIM_PACK(name, source) glob(name) = source;
  GMASIM_LANE_GLOBAL_STATE(GMASIM_PACK)
  GMASIM_LANE_GLOBAL_CONSTANTS(GMASIM_PACK)
#undef GMASIM_PACK
  for (int f = kFail; f < kGlobalFieldCount; ++f) glob(f) = 0.0;
}

// Lane j's Preisach constants (RodConditions::preisach) and its rods' extrema stacks.
void pack_preisach(LaneData& L, std::size_t j, const Conditions& c, const State& s) {
  using namespace lanes;
  const int n = L.st.rods;
  for (int i = 0; i < n; ++i) {
    const RodConditions& rc = c.rods[static_cast<std::size_t>(i)];
    // the law's constants as the scalar law forms them (physics::preisach_constants: 1/a, 1/H_c);
    // M_s^T is the rod's kMsTMag
    const physics::PreisachConstants k = physics::preisach_constants(rc.MsT_mag, rc.preisach);
    auto at = [&](int f) -> double& { return L.pre.field(f, i, n)[j]; };
    at(kPreC) = k.c;
    at(kPreAlpha) = k.alpha;
    at(kPreA) = k.a;
    at(kPreInvA) = k.inv_a;
    at(kPreInvHc) = k.inv_hc;
    at(kPreSigmaU) = k.bins.s;
    for (int b = 0; b <= physics::kPreisachBins; ++b) at(kPreEdge0 + b) = k.bins.edge[b];
    for (int b = 0; b < physics::kPreisachBins; ++b) at(kPreDensity0 + b) = k.bins.density[b];
    L.pre.history(i)[j] = s.rods[static_cast<std::size_t>(i)].preisach;
  }
}

// Lane j's numbers from its model, conditions and state.
void pack_lane(LaneData& L, std::size_t j, const Model& m, const Conditions& c, const State& s,
               const CircuitLowRankView& lr) {
  using namespace lanes;
  auto rod = [&](int f, int i) -> double& { return L.rod(f, i)[j]; };
  const int n = m.rod_count();
  for (int i = 0; i < n; ++i) {
    const RodState& r = s.rods[static_cast<std::size_t>(i)];
    const RodConditions& rc = c.rods[static_cast<std::size_t>(i)];
    const auto& br =
        m.circuit
            .branches[static_cast<std::size_t>(m.circuit.rod_branch[static_cast<std::size_t>(i)])];
    const double q = rc.MsT_mag / rc.Ms_strain_A_per_m;
#define GMASIM_PACK(name, source) rod(name, i) = source;
    GMASIM_LANE_ROD_STATE(GMASIM_PACK)
    GMASIM_LANE_ROD_CONSTANTS(GMASIM_PACK)
#undef GMASIM_PACK
    for (int b = 0; b < n; ++b) L.S(i, b)[j] = lr.S8[static_cast<std::size_t>(8 * i + b)];
    L.bt_coil(i)[j] = lr.bt_coil8[i];
    L.bt_pm(i)[j] = lr.bt_pm8[i];
  }
  pack_globals(L, j, m, c, s);
  if (L.st.preisach) pack_preisach(L, j, c, s);
}

}  // namespace

LaneBatch::LaneBatch(std::span<const Model* const> models,
                     std::span<const Conditions* const> conditions,
                     std::span<const State* const> states)
    : d_(std::make_unique<LaneData>()) {
  const std::size_t n = models.size();
  if (n == 0 || conditions.size() != n || states.size() != n)
    throw InputError(fmt::format("lanes: {} models, {} conditions, {} states: need as many of each",
                                 n, conditions.size(), states.size()));
  std::string why;
  for (const Model* m : models)
    if (!lanes_supported(*m, &why)) throw InputError("lanes: " + why);
  d_->resize(n);
  d_->st = structure_of(*models[0], *conditions[0]);
  if (d_->st.preisach) d_->pre.resize(d_->st.rods, d_->npad);
  for (std::size_t j = 0; j < d_->npad; ++j) {
    const std::size_t src = j < n ? j : n - 1;  // padding repeats the last lane
    const Model& m = *models[src];
    if (j < n && !same_structure(d_->st, structure_of(m, *conditions[src])))
      throw InputError(
          fmt::format("lanes: simulation {} has another structure than simulation 0 "
                      "(rods, magnetisation law, load chains, sensor, mount)",
                      j));
    pack_lane(*d_, j, m, *conditions[src], *states[src], circuit_lowrank_view(m.circuit));
  }
  for (const auto& r : models[0]->rods) rod_names_.push_back(r.name);
  in_current_.assign(d_->npad, 0.0);
  in_dt_.assign(d_->npad, 1.0);
  in_t1_.assign(d_->npad, 0.0);
  in_pm_.assign(d_->npad, 0.0);
}

LaneBatch::~LaneBatch() = default;
LaneBatch::LaneBatch(LaneBatch&&) noexcept = default;
LaneBatch& LaneBatch::operator=(LaneBatch&&) noexcept = default;

std::size_t LaneBatch::size() const { return d_->n; }

void LaneBatch::step(std::span<const double> current_A, std::span<const double> dt_s,
                     std::span<const double> t1_s, bool width_one) {
  const std::size_t n = d_->n;
  if (current_A.size() != n || dt_s.size() != n || t1_s.size() != n)
    throw InputError(fmt::format("lanes: step with {} currents, {} steps, {} times for {} lanes",
                                 current_A.size(), dt_s.size(), t1_s.size(), n));
  pad_inputs(current_A, in_current_);
  pad_inputs(dt_s, in_dt_);
  pad_inputs(t1_s, in_t1_);
  lanes::step_dispatch(*d_, {in_current_.data(), in_dt_.data(), in_t1_.data(), false, nullptr},
                       width_one);
}

// The inputs of the lanes, padding lanes repeating the last lane's (the lanes of its own vector:
// no other lane's branches).
void LaneBatch::pad_inputs(std::span<const double> a, std::vector<double>& to) const {
  std::copy(a.begin(), a.end(), to.begin());
  std::fill(to.begin() + static_cast<std::ptrdiff_t>(a.size()), to.end(), a.back());
}

void LaneBatch::rest_increment(std::span<const double> current_A, std::span<const double> pm_scale,
                               bool width_one) {
  const std::size_t n = d_->n;
  if (current_A.size() != n || pm_scale.size() != n)
    throw InputError(fmt::format("lanes: rest increment with {} currents, {} scales for {} lanes",
                                 current_A.size(), pm_scale.size(), n));
  pad_inputs(current_A, in_current_);
  pad_inputs(pm_scale, in_pm_);
  lanes::step_dispatch(*d_, {in_current_.data(), in_dt_.data(), in_t1_.data(), true, in_pm_.data()},
                       width_one);
}

bool LaneBatch::diverged(std::size_t lane) const { return d_->glob(lanes::kFail)[lane] != 0.0; }
std::size_t LaneBatch::diverged_count() const {
  const double* fail = d_->glob(lanes::kFail);
  return static_cast<std::size_t>(
      std::count_if(fail, fail + d_->n, [](double f) { return f != 0.0; }));
}
std::size_t LaneBatch::full_solves() const { return d_->full_solves; }
std::size_t LaneBatch::newton_solves() const { return d_->lane_solves; }
std::size_t LaneBatch::vector_solves() const { return d_->vector_solves; }

void LaneBatch::unpack(std::size_t j, State& s) const {
  using namespace lanes;
  LaneData& L = *d_;
  for (int i = 0; i < L.st.rods; ++i) {
    RodState& r = s.rods[static_cast<std::size_t>(i)];
#define GMASIM_UNPACK(name, target) target = L.rod(name, i)[j];
    GMASIM_LANE_ROD_STATE(GMASIM_UNPACK)
    if (L.st.preisach) r.preisach = L.pre.history(i)[j];
  }
#undef GMASIM_UNPACK
#define GMASIM_UNPACK(name, target) target = L.glob(name)[j];
  GMASIM_LANE_GLOBAL_STATE(GMASIM_UNPACK)
#undef GMASIM_UNPACK
}

std::size_t LaneBatch::record_width() const {
  return 6 + 9 * static_cast<std::size_t>(d_->st.rods);  // run.cpp's kGlobal + kPerRod per rod
}

void LaneBatch::record_row(std::size_t j, double thermal_expansion_m, double* row) const {
  using namespace lanes;
  LaneData& L = *d_;
  row[0] = L.glob(kT)[j];
  row[1] = L.glob(kCurrent)[j];
  row[2] = L.glob(kY)[j] * 1e6;
  row[3] = L.glob(kBSensor)[j];
  row[4] = thermal_expansion_m * 1e6;
  row[5] = L.glob(kYStack)[j] * 1e6;
  for (int i = 0; i < L.st.rods; ++i) {
    double* b = row + 6 + 9 * i;
    b[0] = L.rod(kH, i)[j];
    b[1] = L.rod(kM, i)[j];
    b[2] = L.rod(kMuR, i)[j];
    b[3] = L.rod(kE, i)[j] * 1e-9;
    b[4] = L.rod(kLambda, i)[j] * 1e6;
    b[5] = L.rod(kF, i)[j];
    b[6] = L.rod(kX, i)[j] * 1e6;
    b[7] = L.rod(kTau, i)[j] * 1e3;
    b[8] = L.rod(kB, i)[j];
  }
}

void LaneBatch::record(std::size_t j, double thermal_expansion_m, TimeSeries& ts) const {
  std::array<double, 6 + 9 * lanes::kMaxRods> row{};
  record_row(j, thermal_expansion_m, row.data());
  for (std::size_t q = 0; q < record_width(); ++q) ts.columns[q].push_back(row[q]);
}

double LaneBatch::y_m(std::size_t lane) const { return d_->glob(lanes::kY)[lane]; }
double LaneBatch::B_T(std::size_t lane) const { return d_->glob(lanes::kBSensor)[lane]; }
double LaneBatch::x_m(std::size_t lane, int rod) const { return d_->rod(lanes::kX, rod)[lane]; }

void LaneBatch::set_time(std::size_t lane, double t_s) { d_->glob(lanes::kT)[lane] = t_s; }

std::string LaneBatch::error(std::size_t j) const {
  using namespace lanes;
  LaneData& L = *d_;
  const auto code = static_cast<int>(L.glob(kFail)[j]);
  if (code == kOk) return "";
  const double t = L.glob(kFailT)[j], v = L.glob(kFailValue)[j], bound = L.glob(kFailBound)[j];
  const int rod_index = static_cast<int>(L.glob(kFailRod)[j]);
  const std::string rod =
      rod_index >= 0 ? rod_names_[static_cast<std::size_t>(rod_index)] : std::string();
  // step()'s check(): |value| <= limit
  auto check = [&](const std::string& where, const char* quantity) -> std::string {
    return DivergenceError(t, where, quantity, v,
                           std::isfinite(v) ? fmt::format("|value| exceeds {:g}", bound)
                                            : std::string("not finite"))
        .what();
  };
  // check_physical_validity's beyond()
  auto beyond = [&](const char* quantity, const char* rule) -> std::string {
    return DivergenceError(t, rod, quantity, v,
                           fmt::format("beyond the physical bound {:.4g}: {}; the model is "
                                       "outside its range (check the values `gmasim model "
                                       "check` warns about)",
                                       bound, rule))
        .what();
  };
  switch (code) {
    case kFailNewton:
      return DivergenceError(t, rod, "field H [A/m] of the consistent magnetic state", v,
                             "Newton's method did not converge")
          .what();
    case kFailCircuit:
      return DivergenceError(t, "", "nodal matrix of the circuit", 0.0, "not positive definite")
          .what();
    case kFailH:
      return check(rod, "H [A/m]");
    case kFailM:
      return check(rod, "M [A/m]");
    case kFailX:
      return check(rod, "x [m]");
    case kFailZ:
      return check("sensor mount", "z [m]");
    case kFailY:
      return DivergenceError(t, "", "output y [m]", v, "not finite").what();
    case kFailBSensor:
      return DivergenceError(t, "", "flux density B [T] of the induction coil", v, "not finite")
          .what();
    case kFailStrain:
      return beyond("magnetostriction lambda [-]",
                    "eq. (11) gives at most 1.5 lambda_s (M/M_s)^2 with |M| <= 1.5 M_s^T");
    case kFailDisplacement:
      return beyond("displacement x [m]", "a rod cannot move by more than its length l^T");
    default:
      return beyond("flux density B [T]", "B = mu0 (H + M) with |M| <= M_s");
  }
}

}  // namespace gmasim
