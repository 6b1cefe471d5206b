#!/usr/bin/env bash
# End-to-end checks of the gmasim CLI: outputs, exit codes and error messages.
# Usage: test_cli.sh <path to gmasim> ; prints "N passed, N failed".
set -u
B="$1"
T="$(mktemp -d)"
trap 'rm -rf "$T"' EXIT
source "$(dirname "$0")/check_lib.sh"
check "simulate default" 0 "stroke +[0-9.]+ um" "$B" simulate --out "$T/a"
[[ -s "$T/a/timeseries.csv" && -s "$T/a/metrics.json" ]] && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: outputs missing"; }
head -1 "$T/a/timeseries.csv" | grep -q '^t_s,current_A,y_um,B_T,xT_um,y_stack_um,rod1_H_A_per_m' && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: csv header"; }
grep -q '"stroke_um"' "$T/a/metrics.json" && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: metrics.json"; }
ls "$T/a" | grep -q tmp && { fail=$((fail + 1)); echo "FAIL: temp files left"; } || pass=$((pass + 1))
check "quantity stats" 0 "rod2_F_N +rms" "$B" simulate --periods 2 --quantity rod2_F_N --out "$T/q"
check "unknown quantity" 2 "unknown quantity 'nope'" "$B" simulate --periods 2 --quantity nope --out "$T/q2"
check "curie" 2 "at or above the Curie temperature" "$B" simulate --temperature 400 --out "$T/b"
check "below absolute zero" 2 "below absolute zero" "$B" simulate --temperature -300 --out "$T/b"
check "frequency" 2 "frequency = 0 Hz: must be in \(0 Hz, 1e\+06 Hz\]" "$B" simulate --frequency 0 --out "$T/b"
printf 't_s,current_A\n0,1\n0.001,abc\n' >"$T/w1.csv"
check "csv non-numeric" 2 "w1.csv:3: non-numeric cell 'abc'" "$B" simulate --waveform "$T/w1.csv" --out "$T/b"
printf 't_s,current_A\n0,1\n0.002,1\n0.001,2\n' >"$T/w2.csv"
check "csv non-monotonic" 2 "w2.csv:4: .*does not increase" "$B" simulate --waveform "$T/w2.csv" --out "$T/b"
: >"$T/w3.csv"
check "csv empty" 2 "w3.csv.*empty" "$B" simulate --waveform "$T/w3.csv" --out "$T/b"
printf 't_s,current_A\n0,-3\n0.01,5\n0.02,-3\n' >"$T/w4.csv"
check "csv waveform runs" 0 "wrote" "$B" simulate --waveform "$T/w4.csv" --out "$T/c"
touch "$T/file"
check "unwritable out" 2 "output directory is not writable" "$B" simulate --out "$T/file/sub"
check "model show" 0 "rod1.ja.k0_A_per_m +3032 +A/m +Table 4" "$B" model show
check "model check ok" 0 "OK" "$B" model check "$(dirname "$0")/../../models/mdma.toml"
# Issue 18: no file is the built-in model; the worse energy ledger closes to <= 1e-6 per cycle.
res="$("$B" model check 2>&1 | sed -nE 's/^energy balance residual: ([0-9.eE+-]+).*/\1/p')"
awk -v r="$res" 'BEGIN { exit !(r != "" && r + 0 <= 1e-6) }' && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: energy balance residual '$res' > 1e-6"; }
check "model check --set" 0 "with --set" "$B" model check --set material.x=0.45
sed 's/^length_m = 0.030  # derived: k_1/length_m = -0.030  # derived: k_1/' "$(dirname "$0")/../../models/mdma.toml" >"$T/bad.toml"
check "negative length" 2 "bad.toml:[0-9]+: rod1.length_m = -0.03 m: must be > 0" "$B" model check "$T/bad.toml"
printf '[meta\nname = 1\n' >"$T/syntax.toml"
check "malformed toml" 2 "syntax.toml:1" "$B" model check "$T/syntax.toml"
# An absurd coil (7.2e9 turns) and a 1000 A step (the largest current allowed): the field
# leaves every bound.
sed 's/^coil_turns = 720.0 /coil_turns = 7.2e9 /' "$(dirname "$0")/../../models/mdma.toml" >"$T/coil.toml"
check "divergence" 3 "diverged at t = 0.001000000 s in rod1: H" "$B" simulate --model "$T/coil.toml" --waveform-kind step --level 1e-6 --step-to 1000 --step-time 0.001 --duration 0.002 --out "$T/d"
grep -q '"status": "diverged"' "$T/d/metrics.json" && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: diverged metrics"; }
check "reproduce quick" 0 "applicable claims pass" "$B" reproduce --quick --no-figures --out "$T/r"
[[ -s "$T/r/report.md" && $(grep -cE '^(stroke|hysteresis|flux)_drop_[0-9]+A,' "$T/r/claims.csv") -eq 12 &&
   $(grep -cE '^(stroke|hysteresis|flux)_drop_slope,' "$T/r/claims.csv") -eq 3 &&
   $(grep -c '^resonance_amplitude,' "$T/r/claims.csv") -eq 1 ]] && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: reproduce outputs"; }
grep -q '| first resonant frequency |' "$T/r/report.md" && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: claims table in report"; }
# --set on every command; model save writes what it ran.
check "set on simulate" 0 "with --set material.Ms_A_per_m=7e5" "$B" simulate --set material.Ms_A_per_m=7e5 --periods 1 --out "$T/set"
check "set unknown" 2 "unknown parameter 'nope'" "$B" sweep --set nope=1 --out "$T/set2"
check "set nan" 2 "'nan' is not a finite number" "$B" frf --set material.Ms_A_per_m=nan --out "$T/set2"
check "set bad option" 2 "options.magnetic_state = .weird.: must be one of: printed, consistent" "$B" track --set options.magnetic_state=weird --out "$T/set2"
check "set rule" 2 "rod1.length_m = -1 m: must be > 0" "$B" ablate --set rod1.length_m=-1 --out "$T/set2"
check "model save" 0 "with 2 changes" "$B" model save --set material.Ms_A_per_m=7e5 --set options.magnetic_state=printed --out "$T/saved.toml"
check "saved model loads" 0 "Ms_A_per_m +700000 .*set: gmasim model save" "$B" model show --model "$T/saved.toml"
check "saved option" 0 "options.magnetic_state +printed" "$B" model show --model "$T/saved.toml"
# Self-heating, compensation and --plot (issue 9).
check "self-heating" 0 "energy: in .* J = stored .* J \+ to ambient" "$B" simulate --self-heating --set thermal_network.coil_heat_capacity_J_per_K=2 --periods 10 --dt 5e-5 --record-every 50 --out "$T/heat"
[[ -s "$T/heat/self_heating.csv" ]] && grep -q '"self_heating"' "$T/heat/metrics.json" && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: self-heating outputs"; }
check "thermal step too long" 2 "fastest time constant" "$B" simulate --self-heating --set thermal_network.coil_heat_capacity_J_per_K=0.01 --periods 2 --out "$T/heat2"
check "compensate" 0 "70.0 +5\.[0-9]+ +-3.0000" "$B" compensate --temperatures 20,70 --reference-current-pp 5 --no-track --periods 2 --out "$T/comp"
check "compensate bad list" 2 "temperatures must increase" "$B" compensate --temperatures 70,20 --no-track --out "$T/comp2"
# Inverse-model feed-forward (issue 20): the evaluation's table and the refused words.
check "feedforward" 0 "100.0 +20.0 +pid_inverse" "$B" track --feedforward inverse --mismatch none --controllers pid,pid_inverse --temperatures 20 --amplitudes 20 --frequencies 100 --out "$T/ff"
head -1 "$T/ff/track.csv" | grep -q '^temperature_C,frequency_Hz,amplitude_um,mismatch,controller,plant_temperature_C,rms_error_um' && [[ -s "$T/ff/track_ratios.csv" ]] && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: feedforward track.csv"; }
check "feedforward bad mismatch" 2 "must be all .*, none .* or both" "$B" track --feedforward inverse --mismatch some --temperatures 20 --out "$T/ff2"
check "feedforward-only flag" 2 "--mismatch applies to the feed-forward evaluation" "$B" track --mismatch none --temperatures 20 --out "$T/ff3"
check "feedforward bad controller" 2 "controller 'lqr': must be pid, pid_temperature or pid_inverse" "$B" track --feedforward inverse --controllers pid,lqr --temperatures 20 --out "$T/ff2"
check "step metrics" 0 "step +y .* rise \(10-90 %\)" "$B" simulate --waveform-kind step --level 0 --step-to 4 --step-time 0.002 --duration 0.01 --out "$T/step"
# --plot needs the Python package of this build (absent in the sanitize-native build).
if compgen -G "$(dirname "$B")/../python/gmasim/_gmasim*.so" >/dev/null; then
  check "plot" 0 "wrote .*frf.png" "$B" frf --method linear --points 8 --temperatures 20 --plot --out "$T/frfplot"
  [[ -s "$T/frfplot/frf.svg" ]] && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: frf.svg"; }
  # identify draws its figures the same way (gmasim.command_figures identify REPORT_DIR).
  "$B" identify synthesize --out "$T/iddata" --temperatures 20 --currents 8 --frequencies 10 \
    --steps-per-period 100 --samples-per-period 50 >/dev/null
  check "identify figures" 0 "weighted RMS" "$B" identify --data "$T/iddata/manifest.toml" \
    --fit material.chi_m:8:50:log --out "$T/id/m.toml" --islands 1 --population 8 --generations 1 \
    --migrate-every 1 --no-refine --no-profile --steps-per-period 100 --threads 1
  ok "identify overlay and convergence figures" test -s "$T/id/m_report/overlay_T20_I8_f10.png" \
    -a -s "$T/id/m_report/overlay_T20_I8_f10.svg" -a -s "$T/id/m_report/convergence.png"
else
  echo "skip: --plot (no Python module in this build)"
fi
# identify --set of an option the start file omits (it adds a line to the start's text): the
# fitted model is written with the fitted values on their lines and carries the option.
"$B" identify synthesize --out "$T/iddata2" --temperatures 20 --currents 8 --frequencies 10 \
  --steps-per-period 100 --samples-per-period 50 >/dev/null
check "identify --set of an omitted option" 0 "weighted RMS" "$B" identify --data "$T/iddata2/manifest.toml" \
  --set options.eddy_law=classical --fit material.chi_m:8:50:log --out "$T/idset/m.toml" --islands 1 \
  --population 8 --generations 1 --migrate-every 1 --no-refine --no-profile --steps-per-period 100 \
  --threads 1 --no-plots
ok "identify --set: option and fitted value in the model" grep -q '^eddy_law = "classical"' "$T/idset/m.toml"
ok "identify --set: the fitted value on its line" grep -q '^chi_m = .*# identified' "$T/idset/m.toml"
# The Freeze switches by their one set of names (kFreezeSwitches).
check "simulate --freeze" 0 "stroke" "$B" simulate --periods 2 --temperature 70 --freeze mu_G,E_t --out "$T/fz"
grep -q '"frozen": \["mu_G", "E_t"\]' "$T/fz/metrics.json" && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: frozen in metrics.json"; }
check "unknown law to freeze" 2 "unknown law 'mu' to freeze; known: mu_G, rho_G, M, E_G, E_t, F_pm, geometry" "$B" simulate --freeze mu --out "$T/fz2"
check "progress eta" 0 "simulate: 100000/100000 \(100 %\), .* s elapsed, ETA" "$B" simulate --periods 10 --progress --out "$T/prog"
check "single-rod template" 0 "OK \(67 parameters, 1 rods" "$B" model check "$(dirname "$0")/../../models/single_rod.toml"
check "single-rod Preisach template" 0 "OK \(67 parameters, 1 rods" "$B" model check "$(dirname "$0")/../../models/single_rod_preisach.toml"
# Shipped models by their bare name, and the list of them (issue 41).
check "model list" 0 "single_rod_preisach +single rod \(Preisach\)" "$B" model list
check "bare model name" 0 "OK \(67 parameters, 1 rods" "$B" model check single_rod_preisach
check "bare --model name" 0 "stroke" "$B" simulate --model single_rod --current-min 0 --periods 1 --out "$T/bare"
check "help has units" 0 "Operating temperature \[degC\]" "$B" simulate --help
# Issue 41: a warning comes after the stdout lines printed before it when both streams go to one
# file (stdout is flushed first): the drift warning at 150 degC follows the run's header.
"$B" simulate --temperature 150 --current-pp 0.5 --periods 1 --out "$T/drift" >"$T/drift.log" 2>&1
h="$(grep -n '^gmasim simulate\|temperature 150' "$T/drift.log" | head -1 | cut -d: -f1)"
w="$(grep -n 'warning: the thermal offset drift' "$T/drift.log" | head -1 | cut -d: -f1)"
[[ -n "$h" && -n "$w" && "$h" -lt "$w" ]] && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: the drift warning (line ${w:-none}) before the header (line ${h:-none})"; }
echo "$pass passed, $fail failed"
[[ $fail -eq 0 ]]
