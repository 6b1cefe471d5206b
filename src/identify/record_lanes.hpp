// The objective's records in SIMD lanes (gmasim/lanes.hpp, docs/lanes.md): the timed,
// current-driven records that start at rest advance together, one lane each, with what
// run_record (record_run.cpp, RecordRun::run_timed) does for one of them -- the same grid
// (StepClock::Spanning), drive, pre-cycles and interpolated samples.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "gmasim/identify/identify.hpp"
#include "identify/objective_runs.hpp"

namespace gmasim::identify_detail {

// Whether run_records_lanes can run the record: current-driven (sine or table), timed, from
// the rest state (initial_state = demagnetised), on a model lanes_supported.
bool record_in_lanes(const Model& m, const Measurement& meas);

// Runs the records (each record_in_lanes) in lanes: response[k] (and B_T[k] if flux[k]) as
// run_record_from_start gives them, their rest states made in lanes too (make_states).
// Throws the DivergenceError of the first record (in time) that diverges.
// drive_A[k] (optional, per record): record_drive's currents of record k (the objective computes
// them once); absent or empty: computed as the steps go.
void run_records_lanes(const Model& m, const std::vector<const Measurement*>& records,
                       const std::vector<bool>& flux, const ObjectiveSettings& s,
                       std::vector<std::vector<double>>& response,
                       std::vector<std::vector<double>>& B_T,
                       const std::vector<const std::vector<double>*>& drive_A = {});

// One candidate's record outputs: response[k] and B_T[k] (if flux[k]) per record.
struct RecordOutputs {
  std::vector<std::vector<double>> response, B_T;
};

// The same records for several models at once (the candidates of a batch evaluation): lane
// k P + c is record k of candidate c, so that a vector of lanes holds one record across the
// candidates. out[c] is what run_records_lanes(*candidates[c], ...) gives, bit for bit (each
// lane is the width-1 kernel's; no lane reads another). With `failed`, a candidate whose record
// diverges gets failed[c] = 1 (its outputs unspecified) and the others go on; without it, the
// first divergence throws as above. Rest states that fail throw (make_states).
void run_records_lanes(std::span<const Model* const> candidates,
                       const std::vector<const Measurement*>& records,
                       const std::vector<bool>& flux, const ObjectiveSettings& s,
                       std::vector<RecordOutputs>& out, std::vector<char>* failed,
                       const std::vector<const std::vector<double>*>& drive_A = {});

// The coil current of a timed, current-driven record at the times t_1 .. t_steps of its grid (one
// pass; element 0 unused), as run_records_lanes computes them step by step (the same operations,
// the same bits): what the objective computes once per record. Empty for a record of more than
// kMaxStoredDriveSteps steps.
std::vector<double> record_drive(const Measurement& meas, const ObjectiveSettings& s);

}  // namespace gmasim::identify_detail
