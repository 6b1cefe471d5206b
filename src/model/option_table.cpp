// The model options' table (gmasim/model/parameters.hpp, option_table): each option's key, its
// words and what each means, and where it lands in Options. To add an option: a row here, its
// field in Options (gmasim/model/model.hpp) and, unless it may be omitted, its line in the model
// files.
#include <type_traits>

#include "gmasim/model/model.hpp"
#include "gmasim/model/parameters.hpp"

namespace gmasim {
namespace {

// ---- options ----------------------------------------------------------------------------
template <auto P>
void set_option(Options& o, int v) {
  using T = std::remove_reference_t<decltype(o.*P)>;
  o.*P = static_cast<T>(v);
}
template <auto P>
int get_option(const Options& o) {
  return static_cast<int>(o.*P);
}
#define OPTION(field) &set_option<&Options::field>, &get_option<&Options::field>, "Options::" #field

constexpr OptionChoice kBoolean[] = {{"false", 0, "off"}, {"true", 1, "on"}};
constexpr OptionChoice kStressSign[] = {
    {"compression_negative", static_cast<int>(StressSign::CompressionNegative),
     "the Zheng/Zhou form of eq. (6): compression is negative"},
    {"compression_positive", static_cast<int>(StressSign::CompressionPositive),
     "sigma in eq. (3), (6), (13) is the compressive magnitude, as eq. (11)-(12) use sigma_p"},
};
constexpr OptionChoice kEq10Scale[] = {
    {"room_referenced", static_cast<int>(Eq10Scale::RoomReferenced),
     "p(T) = p0 f(T)/f(T_ref), T and T_c in K: Table 4 holds at T_ref for every law"},
    {"kelvin", static_cast<int>(Eq10Scale::Kelvin), "T/T_c in K: Table 4 holds at 0 K"},
    {"celsius", static_cast<int>(Eq10Scale::Celsius), "T/T_c in degC, the literal print"},
};
constexpr OptionChoice kShapeLaw[] = {
    {"printed", static_cast<int>(ShapeLaw::Printed), "a^T = a0 exp(-T/(beta3 T_c)), as printed"},
    {"mean_field", static_cast<int>(ShapeLaw::MeanField),
     "a^T = a0 T/T_ref (kelvin), mean-field theory; needs room_referenced"},
};
constexpr OptionChoice kMagneticState[] = {
    {"printed", static_cast<int>(MagneticState::Printed), "eq. (2), (3), (7) as printed"},
    {"consistent", static_cast<int>(MagneticState::Consistent),
     "each rod carries the flux of its own state, B = mu0 (H + M)"},
};
constexpr OptionChoice kMagnetisationLaw[] = {
    {"jiles_atherton", static_cast<int>(MagnetisationLaw::JilesAtherton),
     "Jiles-Atherton, eq. (9)-(10): the [<rod>.ja] tables"},
    {"preisach", static_cast<int>(MagnetisationLaw::Preisach),
     "Preisach, log-normal coercive and Gaussian interaction fields: the [<rod>.preisach] "
     "tables"},
};
constexpr OptionChoice kEq11Saturation[] = {
    {"temperature", static_cast<int>(Eq11Saturation::Temperature),
     "M normalised by M_s^T, as printed"},
    {"reference", static_cast<int>(Eq11Saturation::Reference),
     "M normalised by M_s at T_ref: the strain follows the magnetisation"},
};
constexpr OptionChoice kEddyLaw[] = {
    {"table4", static_cast<int>(EddyLaw::Table4),
     "kappa = (r1^2 - r2^2)/(4 k_j rho) with Table 4's k_j, as printed"},
    {"classical", static_cast<int>(EddyLaw::Classical),
     "the classical quasi-static eddy field of a tube, section-averaged (r^2/(8 rho) for a solid "
     "rod); k_j unused"},
};

constexpr OptionChoice kSensorMountBase[] = {
    {"recoil", static_cast<int>(SensorMountBase::Recoil),
     "the housing's recoil moves the bracket; the sensor reads y_stack + (z - q)"},
    {"output", static_cast<int>(SensorMountBase::Output),
     "the actuator's output moves the bracket (the probe rides on it); the sensor reads z"},
};

constexpr OptionChoice kJointMechanics[] = {
    {"rigid", static_cast<int>(JointMechanics::Rigid),
     "the joints carry no compliance: the gap is magnetic only (eq. 15-18 as printed)"},
    {"bonded", static_cast<int>(JointMechanics::Bonded),
     "each rod's joints are a bond line of thickness joint_gap_m and modulus joint_modulus_Pa, a "
     "compliance in series with the rod (eq. 17)"},
};

const OptionDef kOptions[] = {
    {"stress_sign", false, kStressSign, OPTION(stress_sign),
     "the sign convention of the prestress in eq. (3), (6), (13)"},
    {"eq10_temperature_scale", false, kEq10Scale, OPTION(eq10_scale),
     "the temperature scale of T/T_c in eq. (10) and where Table 4 holds"},
    {"eq10_shape_law", false, kShapeLaw, OPTION(shape_law), "the law of the JA shape a^T"},
    {"magnetic_state", false, kMagneticState, OPTION(magnetic_state),
     "how a rod's flux, field and magnetisation relate (docs/model.md, \"Magnetic state\")"},
    {"eq11_saturation", false, kEq11Saturation, OPTION(eq11_saturation),
     "the M_s that normalises M in eq. (11)"},
    {"thermal_expansion_in_output", true, kBoolean, OPTION(thermal_expansion_in_output),
     "add the thermal expansion x_T of eq. (21) to the output (section 4.4.2 removes it)"},
    {"geometry_thermal_expansion", true, kBoolean, OPTION(geometry_thermal_expansion),
     "use l^T, A^T, r^T in eq. (2), (7), (17), (19)"},
    {"magnetisation_law", false, kMagnetisationLaw, OPTION(magnetisation_law),
     "the hysteresis law of the rods (docs/model.md, \"Magnetisation laws\"); may be omitted",
     "jiles_atherton"},
    {"eddy_law", false, kEddyLaw, OPTION(eddy_law),
     "the eddy-current coefficient kappa of eq. (7) (docs/model.md, \"The eddy law\"); may be "
     "omitted",
     "table4"},
    {"sensor_mount_base", false, kSensorMountBase, OPTION(sensor_mount_base),
     "what moves the sensor mount's bracket (docs/model.md, \"The sensor mount\"); may be "
     "omitted",
     "recoil"},
    {"joint_mechanics", false, kJointMechanics, OPTION(joint_mechanics),
     "the mechanics of the rods' joints (docs/model.md, \"The joints\"); may be omitted", "rigid"},
};

#undef OPTION

}  // namespace

std::span<const OptionDef> option_table() { return kOptions; }

}  // namespace gmasim
