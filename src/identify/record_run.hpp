// Simulating one measurement record with the objective's rules (docs/data.md, "What is
// simulated and compared"). Used by the objective, the fit report and synthesize.
#pragma once

#include <cstddef>
#include <vector>

#include "gmasim/identify/identify.hpp"

namespace gmasim::identify_detail {

// The objective's time step: dt_s if set, else period / steps_per_period for periodic
// runs, else kMaxDt_s.
double objective_step(const ObjectiveSettings& s, double period_s);

// The rod of the record's field_A_per_m / strain_ppm column (condition key `rod`; the
// first rod if none). Throws InputError naming the model's rods.
std::size_t record_rod(const Model& m, const Measurement& meas);

// The coil current of the state the record starts from (make_state): the first current,
// the sine at the first time, or 0 for a field record (which then ramps to its first field).
double record_initial_current(const Measurement& meas);

// The amplitude A of the record's initial cycle (initial_state): the largest |drive| (the
// biased sine's largest |current| with current_source = sine).
double record_drive_amplitude(const Measurement& meas);

// Steps or quasi-static increments one simulation of the record takes (pre-cycling
// included): checked against kMaxSteps before any evaluation.
double record_step_count(const Measurement& meas, const ObjectiveSettings& s);

// Runs the record from st (make_state at record_initial_current) and returns the response
// in the record's unit (um or ppm) and, if given, the induction-coil flux density B_T [T]
// and the record rod's applied field H_c (eq. 7) [A/m] at every sample. Offsets are not
// applied here (apply_offset). Throws DivergenceError / InputError.
void run_record(const Model& m, const Conditions& c, State st, const Measurement& meas,
                const ObjectiveSettings& s, std::vector<double>& response, std::vector<double>* B_T,
                std::vector<double>* H_A_per_m = nullptr);

// The model a record measured at its own prestress (condition key prestress_MPa) is simulated
// with: m with the preload force that gives the first rod of stack.rods that stress at T_ref
// (force = prestress x A_1, as the model key preload.prestress_MPa). Its preload replaces the
// model's, free fit parameter or not. Throws InputError if the record has no prestress.
Model with_record_preload(const Model& m, const MeasurementCondition& c);

// Shifts `simulated` by the record's offset rule so that simulated - measured is the
// residual: FirstSample aligns the first samples, Fitted removes the least-squares constant
// over the compared samples [begin, n). Returns the constant added (0 for Absolute).
double apply_offset(OffsetMode mode, const std::vector<double>& measured, std::size_t begin,
                    std::vector<double>& simulated);

}  // namespace gmasim::identify_detail
