#!/usr/bin/env bash
# Regression tests of issue 19 ("Hardening II"), numbered as its items: no output destroys an
# input, no accepted input gives a physically impossible answer, every signal and resource limit
# is handled, every message names its flag. Each check asserts the exit code and the message
# (and, where it matters, that an input is unchanged or nothing is left behind).
# Usage: hardening_cli.sh <path to gmasim>. About 30 s.
set -u
B="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
SRC="$(cd "$(dirname "$0")/../.." && pwd)"
T="$(mktemp -d)"
trap 'rm -rf "$T"' EXIT
cd "$T"
source "$SRC/tests/cli/check_lib.sh"
# ulimit -v does not mix with AddressSanitizer's shadow memory: those checks need a plain build.
SANITIZED=0
if ldd "$B" 2>/dev/null | grep -q libasan || grep -aq __asan_init "$B" 2>/dev/null; then SANITIZED=1; fi
sha() { sha256sum "$1" | cut -d' ' -f1; }
unchanged() {  # name, file, the hash it had
  ok "$1" test "$(sha "$2")" = "$3"
}

# ---- inputs of the identify checks -----------------------------------------------------------
"$B" identify synthesize --out syn --temperatures 20 --currents 8 --frequencies 10 --periods 1.5 \
  --samples-per-period 40 --steps-per-period 100 --no-flux >/dev/null
printf '[[parameter]]\nname = "material.lambda_s"\nlower = 0.8e-3\nupper = 1.2e-3\n' >fit.toml
ID=(identify --islands 1 --population 8 --migrate-every 1 --generations 1 --no-refine --no-plots
    --quiet --steps-per-period 100 --threads 1)
printf 't_s,current_A\n0,-3\n0.005,5\n0.01,-3\n' >w.csv

# ---- 1. no output overwrites an input --------------------------------------------------------
h=$(sha syn/manifest.toml)
check "1 identify --out = the manifest" 2 "--out syn/manifest.toml: would overwrite the input --data syn/manifest.toml" \
  "$B" "${ID[@]}" --data syn/manifest.toml --fit fit.toml --out syn/manifest.toml
unchanged "1 the manifest is unchanged" syn/manifest.toml "$h"
csv=$(ls syn/*.csv | head -1)
h=$(sha "$csv")
check "1 identify --out = a measurement CSV" 2 "would overwrite the input --data \(a measurement file\)" \
  "$B" "${ID[@]}" --data syn/manifest.toml --fit fit.toml --out "$csv"
unchanged "1 the CSV is unchanged" "$csv" "$h"
h=$(sha fit.toml)
check "1 identify --out = the fit spec (another spelling)" 2 "would overwrite the input --fit fit.toml" \
  "$B" "${ID[@]}" --data syn/manifest.toml --fit fit.toml --out ./fit.toml
unchanged "1 the fit spec is unchanged" fit.toml "$h"
check "1 --out and --checkpoint the same file" 2 "--checkpoint same.toml: the same file as --out same.toml; two outputs" \
  "$B" "${ID[@]}" --data syn/manifest.toml --fit fit.toml --out same.toml --checkpoint same.toml
ok "1 nothing written" test ! -e same.toml
mkdir -p o && cp w.csv o/timeseries.csv
h=$(sha o/timeseries.csv)
check "1 simulate: the waveform is the timeseries.csv it would write" 2 "--out o/timeseries.csv: would overwrite the input --waveform" \
  "$B" simulate --waveform o/timeseries.csv --out o
unchanged "1 the waveform is unchanged" o/timeseries.csv "$h"
mkdir -p hl && ln w.csv hl/timeseries.csv
check "1 simulate: a hard link to the waveform" 2 "would overwrite the input --waveform w.csv" \
  "$B" simulate --waveform w.csv --out hl
cp "$SRC/models/mdma.toml" m.toml
h=$(sha m.toml)
check "1 model save over its own model" 2 "--out ./m.toml: would overwrite the input --model m.toml" \
  "$B" model save --model m.toml --set material.chi_m=20 --out ./m.toml
unchanged "1 the model is unchanged" m.toml "$h"
mkdir -p syn2 && cp "$SRC/models/mdma.toml" syn2/truth.toml
check "1 synthesize over its model (named as its truth.toml)" 2 "would overwrite the input --model syn2/truth.toml" \
  "$B" identify synthesize --model syn2/truth.toml --out syn2 --temperatures 20 --currents 8 --frequencies 10
printf '### x\nwhy\n' >notes.md
check "1 reproduce --doc = --doc-notes" 2 "--doc notes.md: would overwrite the input --doc-notes notes.md" \
  "$B" reproduce --quick --no-figures --doc notes.md --doc-notes notes.md --out rep
check "1 sweep into the directory of its model" 2 "would overwrite the input --model sweep_model.toml" \
  bash -c "cp m.toml sweep_model.toml && '$B' sweep --model sweep_model.toml --temperatures 20 --currents 8 --periods 1 --out ."

# ---- 2. the smallest step ----------------------------------------------------------------------
check "2 --dt 1e-28" 2 "dt = 1e-28 s \(--dt, dt_s\): must be in \[1e-12, 0.001\] s" \
  "$B" simulate --waveform-kind dc --level 0 --duration 1e-24 --dt 1e-28 --out s2
check "2 a duration shorter than one step" 2 "duration = 1e-24 s \(--duration\): shorter than one time step" \
  "$B" simulate --waveform-kind dc --level 0 --duration 1e-24 --out s2
check "2 a denormal --dt" 2 "must be in \[1e-12, 0.001\] s" "$B" simulate --dt 4.9e-324 --out s2
check "2 20 steps per period" 2 "gives 20 steps per period at 100 Hz: at least 100 are needed" \
  "$B" simulate --frequency 100 --dt 5e-4 --out s2
ok "2 nothing written" test ! -e s2/timeseries.csv

# ---- 3. physically impossible results ---------------------------------------------------------
check "3 E_s = 1 kPa: the guard ends the run" 3 "in rod[0-9]: magnetostriction lambda \[-\] = .*beyond the physical bound" \
  "$B" simulate --set material.Es_Pa=1e3 --periods 1 --out s3
check "3 E_s = 1 kPa: and a warning at load" 3 "warning: .*material.Es_Pa = 1000 Pa: far outside Terfenol-D's modulus" \
  "$B" simulate --set material.Es_Pa=1e3 --periods 1 --out s3
check "3 a crushing preload" 2 "preload.force_N = 1e\+09 N gives rod 'rod[0-9]' a prestress of .* beyond the compressive strength" \
  "$B" simulate --set preload.force_N=1e9 --periods 1 --out s3b

# ---- 4. identify: limits and SIGTERM during its first population ------------------------------
ID4=(identify --migrate-every 1 --generations 1 --no-refine --no-plots --quiet --steps-per-period 100
     --data syn/manifest.toml --fit fit.toml --out m4.toml)
check "4 --population 1e8" 2 "--population 100000000: at most 100000 individuals per island" \
  "$B" "${ID4[@]}" --population 100000000
check "4 identify --threads -1" 2 "--threads -1: must be 0 \(all cores\) or" \
  "$B" "${ID4[@]}" --threads -1
check "4 sweep --threads -1" 2 "threads = -1 \(--threads\): must be 0 \(all cores\) or in \[1, 1024\]" \
  "$B" sweep --threads -1 --temperatures 20 --currents 8 --periods 1 --out sw4
check "4 --islands 3000" 2 "--islands 3000: at most 256 per rank" "$B" "${ID4[@]}" --islands 3000
# The first population of 20000 individuals takes far longer (~10 s) than the 0.5 s we wait.
start=$(date +%s%N)
"$B" identify --islands 1 --population 20000 --generations 1 --no-refine --no-plots --quiet \
  --steps-per-period 100 --threads 1 --data syn/manifest.toml --fit fit.toml --out m4.toml 2>sig4.txt &
pid=$!
sleep 0.5
kill -TERM "$pid"
wait "$pid"
rc=$?
took_ms=$((($(date +%s%N) - start) / 1000000))
ok "4 SIGTERM in the first population: exit 130 (rc $rc)" test "$rc" -eq 130
ok "4 ... within 5 s (${took_ms} ms)" test "$took_ms" -lt 5500
ok "4 ... the best model so far is written" test -s m4.toml
ok "4 ... it says so" grep -q "interrupted: wrote the best model so far" sig4.txt

# ---- 5. one set per run, signals during writes, stale temporaries, ulimit -f -------------------
# Two equally long runs (a565ea1 mixed their pairs in 4 of 40 such rounds on this machine).
bad=0
for round in $(seq 1 20); do
  "$B" simulate --periods 1 --frequency 100 --current-pp 6 --out cc >/dev/null 2>&1 &
  p1=$!
  "$B" simulate --periods 1 --frequency 100 --current-pp 8 --out cc >/dev/null 2>&1 &
  p2=$!
  wait "$p1" "$p2"
  /usr/bin/python3 - cc <<'EOF' || bad=$((bad + 1))
import json, sys, pathlib
d = pathlib.Path(sys.argv[1])
data = (d / "timeseries.csv").read_bytes()
h = 14695981039346656037
for c in data:
    h = ((h ^ c) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
m = json.loads((d / "metrics.json").read_text())["timeseries_csv"]
sys.exit(0 if m == {"bytes": len(data), "fnv1a64": f"{h:016x}"} else 1)
EOF
done
ok "5 two runs on one --out: always one run's pair ($bad of 20 mixed)" test "$bad" -eq 0
mkdir -p st
dead=$(sh -c 'echo $$')  # a process that has ended
echo partial >"st/timeseries.csv.tmp.$dead"
check "5 a run" 0 "wrote" "$B" simulate --periods 1 --out st
ok "5 it removed the stale temporary of process $dead" test ! -e "st/timeseries.csv.tmp.$dead"
# SIGINT at 50-95 % of an undisturbed run's time: mostly while its 40 MB timeseries.csv is
# written (a565ea1 left a timeseries.csv.tmp.<pid> in 2 of these 6).
t0=$(date +%s%N)
"$B" simulate --periods 10 --out sg_timing >/dev/null 2>&1
run_ms=$((($(date +%s%N) - t0) / 1000000))
left=0
for pct in 50 60 70 80 90 95; do
  rm -rf sg
  "$B" simulate --periods 10 --out sg >/dev/null 2>sg.txt &
  pid=$!
  sleep "$(printf '%d.%03d' $((run_ms * pct / 100000)) $((run_ms * pct / 100 % 1000)))"
  kill -INT "$pid" 2>/dev/null
  wait "$pid"
  if ls sg 2>/dev/null | grep -q tmp; then left=$((left + 1)); fi
done
ok "5 SIGINT during a write leaves no temporary ($left of 6 left one)" test "$left" -eq 0
check "5 ulimit -f: reported, not killed by SIGXFSZ" 2 "timeseries.csv: cannot write output \(File too large: the file size limit \(ulimit -f\) is 102400 bytes\)" \
  bash -c "ulimit -f 100; exec '$B' simulate --periods 3 --out fz"
ok "5 ... and no temporary left" test -z "$(ls fz 2>/dev/null | grep tmp)"

# ---- 6. synthesize accepts what identify accepts ------------------------------------------------
check "6 synthesize --steps-per-period 3" 2 "steps per period 3 \(--steps-per-period\): must be >= 8" \
  "$B" identify synthesize --out sy6 --temperatures 20 --currents 8 --frequencies 10 --steps-per-period 3
check "6 synthesize --currents 0" 2 "current peak-to-peak 0 A \(--currents\): must be in \(0, 2000\] A" \
  "$B" identify synthesize --out sy6 --temperatures 20 --currents 0 --frequencies 10
ok "6 nothing written" test ! -e sy6/manifest.toml

# ---- 7. memory before the run -------------------------------------------------------------------
printf 't_s,current_A\n0,0\n50,1\n100,0\n' >ms.csv  # a waveform in ms, given as seconds
if [[ $SANITIZED -eq 0 ]]; then
  check "7 a record that does not fit in memory" 2 "simulation: recording 1e\+07 rows x 33 columns .* needs about .* GB of memory; .* available \(RLIMIT_AS \(ulimit -v\)\): record less often \(--record-every" \
    bash -c "ulimit -v 2000000; exec '$B' simulate --waveform ms.csv --out s7"
fi

# ---- 8. computable and validated ranges -------------------------------------------------------
check "8 300 degC: outside the computable range, which is named" 2 "temperature 300 degC: outside the range where models/mdma.toml \(built-in\) can be computed, \[-?[0-9.]+, [0-9.]+\] degC" \
  "$B" simulate --temperature 300 --periods 1 --out s8
check "8 180 degC: runs, with a warning" 0 "warning: --temperature 180 degC: outside the range where models/mdma.toml \(built-in\) was validated, \[20, 150\] degC" \
  "$B" simulate --temperature 180 --periods 1 --out s8
check "8 model show prints both ranges" 0 "# temperatures: computable \[.*\] degC .*; validated \[20, 150\] degC" "$B" model show
check "8 model check prints both ranges" 0 "temperatures: computable .*validated \[20, 150\] degC" "$B" model check "$SRC/models/mdma.toml"

# ---- 9. dimensional keys carry their unit --------------------------------------------------------
check "9 --set rod1.length=50" 2 "--set 'rod1.length=50': .*parameter 'rod1.length' has a unit: write 'rod1.length_m' \(the value in m\)" \
  "$B" simulate --set rod1.length=50 --out s9
check "9 a fit spec name without its unit" 2 "write 'rod1.ja.k0_A_per_m'" \
  "$B" "${ID[@]}" --fit 'rod1.ja.k0:1000:5000' --data syn/manifest.toml --out m9.toml
check "9 a dimensionless key keeps its name" 0 "wrote" "$B" simulate --set material.chi_m=20 --periods 1 --out s9

# ---- 10. flags the waveform does not use ----------------------------------------------------------
check "10 --waveform with --frequency" 1 "--frequency: this run's waveform is --waveform w.csv, which does not use it" \
  "$B" simulate --waveform w.csv --frequency 100 --out s10
check "10 --waveform with --waveform-kind" 1 "--waveform-kind sine with --waveform w.csv: the CSV is the whole current waveform" \
  "$B" simulate --waveform w.csv --waveform-kind sine --out s10
check "10 --waveform-kind dc with --current-pp" 1 "--current-pp: this run's waveform is --waveform-kind dc, which does not use it \(only --waveform-kind sine do\)" \
  "$B" simulate --waveform-kind dc --current-pp 5 --duration 0.01 --out s10

# ---- 11. messages name the flag, the file or the key --------------------------------------------
check "11 --dt 1" 2 "dt = 1 s \(--dt, dt_s\): must be in" "$B" simulate --dt 1 --out s11
check "11 --record-every 1e8" 2 "record_every = 100000000 \(--record-every\) .* the metrics need at least 3" \
  "$B" simulate --record-every 100000000 --out s11
check "11 thermal expansion to a negative length" 2 "thermal expansion of rod 'rod1' \(material.alpha_thermal_per_K = 0.01 1/K\) makes its length" \
  "$B" simulate --set material.alpha_thermal_per_K=0.01 --temperature -200 --periods 1 --out s11
awk '/^rod = "rod2"/ && !done {sub(/rod2/, "rod1"); done = 1} {print}' "$SRC/models/mdma.toml" >two.toml
check "11 a rod in two branches: names, lines" 2 "two.toml:[0-9]+: circuit branch '.*' carries rod 'rod1', which branch '.*' \(line [0-9]+\) already carries" \
  "$B" model check two.toml
printf 't_s,current_A\n0,0\n0.001,1000.0001\n' >w_big.csv
check "11 a waveform value out of range: file:line, the value" 2 "w_big.csv:3: current_A = 1000.0001 A: must be in \[-1000, 1000\] A" \
  "$B" simulate --waveform w_big.csv --out s11
check "11 --out ''" 1 "--out '': an empty value \(give a value, or leave the flag out for its default\)" "$B" simulate --periods 1 --out ''
# an empty value is refused for every flag that takes one: a number ('' was 0), a path ('' was
# the default), a list ('' was one 0)
check "11 --current-min ''" 1 "--current-min '': an empty value" "$B" simulate --periods 1 --current-min '' --out s11e
check "11 --model ''" 1 "--model '': an empty value" "$B" simulate --periods 1 --model '' --out s11e
check "11 sweep --temperatures ''" 1 "--temperatures '': an empty value" "$B" sweep --temperatures '' --out s11e
check "11 --threads ''" 1 "--threads '': an empty value" "$B" sweep --threads '' --out s11e
ok "11 a refused empty value leaves no output" test ! -e s11e
check "11 a mistyped command" 1 "unknown command 'simulat' \(did you mean 'simulate'\?\)" "$B" simulat
check "11 a mistyped flag" 1 "gmasim simulate: unknown flag --temprature \(did you mean --temperature\?\)" \
  "$B" simulate --temprature 20
check "11 a unit in a number" 1 "--temperature '80C': not a number \(in degC, without the unit\)" \
  "$B" simulate --temperature 80C

# ---- 12. the audit of stop 34: counts, sizes and files from typed numbers --------------------------
check "12 --thermal-step 1e14 (overflowed to one 10 us step)" 2 \
  "thermal step \(--thermal-step\) = 1e\+14 s: longer than the thermal network's fastest time constant" \
  "$B" simulate --self-heating --thermal-step 1e14 --periods 2 --out s12
check "12 two temperatures, one directory name" 2 \
  "--temperature: 20 and 20.000000100000001 degC both write s12/T20C: give distinct temperatures" \
  "$B" simulate --temperature 20,20.0000001 --periods 1 --out s12
check "12 a bad temperature last in the list: refused before the first run" 2 "temperature 250 degC: outside" \
  "$B" simulate --temperature 20,250 --periods 1 --out s12
ok "12 ... and nothing of the refused runs is left" test ! -e s12
check "12 synthesize: two records of one name" 2 "two records are both named T20_I8_f10.csv" \
  "$B" identify synthesize --out s12 --currents 8,8.0000001 --frequencies 10 --temperatures 20
check "12 sensitivity: --json and --csv one file" 2 "--csv x.out: the same file as --json x.out" \
  "$B" sensitivity --param thermal_expansion.sleeve_length_m --claim thermal_model --json x.out --csv x.out
mkfifo fifo
check "12 a FIFO nobody writes: refused after 10 s, no hang" 2 "fifo: model file is a FIFO that nobody wrote to within 10 s" \
  timeout 30 "$B" model check fifo
mkfifo fifo2
(sleep 1; cat "$SRC/models/single_rod.toml" >fifo2) &
check "12 a FIFO whose writer starts a moment later: read whole" 0 "fifo2: OK|fifo2: valid|OK" timeout 30 "$B" model check fifo2
wait
mkdir -p pre/existing
check "12 a refused run through new/../existing/sub" 2 "nonexist.toml" \
  "$B" reproduce --quick --no-figures --out pre/new/../existing/sub --compare nonexist.toml
ok "12 ... removes what it made and keeps the directory that existed" test -d pre/existing -a ! -e pre/new
check "12 track: a PID log of 1e8 rows" 2 "track: 1e\+08 PID samples in the longest run .* \(limit 2e\+07 rows\)" \
  "$B" track --temperatures 20 --amplitudes 10 --frequencies 10 --periods 1 --sample-rate 1e9 --out s12
check "12 track: --dt above the PID sample period (was clamped)" 2 \
  "dt = 1e\+308 s \(--dt\): longer than the PID sample period" \
  "$B" track --temperatures 20 --amplitudes 10 --frequencies 10 --periods 1 --dt 1e308 --out s12
for st in -1 0 0.01 1e308; do
  check "12 --step-time $st: no step inside the run" 2 "step time = .* \(--step-time\): must be inside the run, 0 < t < 0.01 s" \
    "$B" simulate --waveform-kind step --step-time "$st" --level 0 --step-to 1 --duration 0.01 --out s12
done
check "12 chirp: offset + amplitude beyond the current limit" 2 "chirp maximum \(offset \+ amplitude\) = 1800 A" \
  "$B" simulate --waveform-kind chirp --offset 900 --amplitude 900 --duration 0.01 --out s12
check "12 frf: bias + amplitude beyond the current limit" 2 "peak current \(--bias \+ --amplitude\) = 1000.9999 A" \
  "$B" frf --bias 999.9999 --amplitude 1 --out s12
check "12 params-vs-temperature: a diverged run is diagnosed (was NaN, exit 0)" 3 \
  "params-vs-temperature: the run at 20 degC, .* diverged: diverged at t = .* H \[A/m\]" \
  "$B" params-vs-temperature --model "$SRC/models/single_rod.toml" --set circuit.branches.coil.coil_turns=1e20 \
  --temperatures 20,70 --periods 1 --out s12
ok "12 refused and diverged runs leave no empty output directory" test ! -e s12
check "12 identify: --report = --out (the fit was lost after the search)" 2 "--report o12.toml: the same file as --out o12.toml" \
  "$B" "${ID[@]}" --data syn/manifest.toml --fit fit.toml --out o12.toml --report o12.toml
mkdir -p d12
check "12 identify: --out is a directory, refused before the search" 2 "--out d12: is a directory; name the file to write" \
  "$B" "${ID[@]}" --data syn/manifest.toml --fit fit.toml --out d12
check "12 identify: --checkpoint-every 0" 2 "--checkpoint-every 0: must be >= 1" \
  "$B" "${ID[@]}" --data syn/manifest.toml --fit fit.toml --out o12.toml --checkpoint c12.ckpt --checkpoint-every 0
check "12 identify: --fd-step 1e-300 (a Jacobian of rounding)" 2 "--fd-step 1e-300: must be in \[1e-8, 0.1\)" \
  "$B" "${ID[@]}" --data syn/manifest.toml --fit fit.toml --out o12.toml --fd-step 1e-300
ok "12 ... and no output of the refused fits" test ! -e o12.toml
awk '/frequency_Hz = / && !done {sub(/frequency_Hz = [0-9.]+/, "frequency_Hz = 0.0"); done = 1} {print}' \
  "$SRC/data/claims.toml" >claims0.toml
check "12 a claim's condition the study cannot hold: file:line" 2 "claims0.toml:[0-9]+: .*frequency_Hz = 0: must be > 0" \
  "$B" reproduce --quick --no-figures --claims claims0.toml --out r12
check "12 reproduce --compare: read before the study" 2 "nonexist.toml" \
  "$B" reproduce --quick --no-figures --compare nonexist.toml --out r12
ok "12 ... and no report of the refused studies" test ! -e r12
check "12 reproduce --python that cannot run (was exit 0, a note in report.md)" 2 \
  "--python /nonexistent: not an executable .* or --no-figures" "$B" reproduce --quick --python /nonexistent --out r12
check "12 track --seed -1 (wrapped to 2^64 - 1)" 1 "--seed -1: must be >= 0" \
  "$B" track --temperatures 20 --amplitudes 10 --frequencies 10 --periods 1 --seed -1 --out r12
check "12 track --seed beyond 64 bits (saturated)" 1 "--seed 99999999999999999999999: out of range" \
  "$B" track --temperatures 20 --amplitudes 10 --frequencies 10 --periods 1 --seed 99999999999999999999999 --out r12
check "12 track --seed in hex beyond 64 bits (CLI11 reads 0x)" 1 "--seed 0x1FFFFFFFFFFFFFFFFFFF: out of range" \
  "$B" track --temperatures 20 --amplitudes 10 --frequencies 10 --periods 1 --seed 0x1FFFFFFFFFFFFFFFFFFF --out r12
check "12 a whole number below an int flag's range" 1 "--threads -99999999999999999999: out of range \(too small" \
  "$B" sweep --threads -99999999999999999999 --out r12
check "12 a whole number out of an int flag's range: not 'not a whole number'" 1 \
  "--threads 2147483648: out of range" "$B" sweep --threads 2147483648 --out r12
check "12 ablate --current-pp 0 (inf % of no stroke)" 2 "current peak-to-peak \(--current-pp\) = 0 A: must be > 0" \
  "$B" ablate --frequencies 10 --periods 1 --current-pp 0 --out r12
check "12 params-vs-temperature --retention-currents 0" 2 \
  "retention current peak-to-peak \(--retention-currents\) = 0 A: must be > 0" \
  "$B" params-vs-temperature --retention-currents 0 --out r12
check "12 --ambient without --self-heating (ignored)" 1 "--ambient: only a self-heating run uses it" \
  "$B" simulate --ambient 30 --periods 1 --out r12
check "12 compensate --no-track with a tracking flag (ignored)" 1 "(--no-track excludes --track-amplitudes|--track-amplitudes excludes --no-track)" \
  "$B" compensate --no-track --track-amplitudes 5 --out r12
check "12 identify --checkpoint-every without --checkpoint (ignored)" 1 "--checkpoint-every requires --checkpoint" \
  "$B" "${ID[@]}" --data syn/manifest.toml --fit fit.toml --out o12.toml --checkpoint-every 3
for f in "--bias 1e308|tracking bias current \(--bias\)" "--current-limit 0|tracking current limit \(--current-limit\) = 0 A" \
         "--track-amplitudes 0|tracking amplitude \(--track-amplitudes\) = 0 um" \
         "--track-frequencies 0|tracking frequency \(--track-frequencies\) = 0 Hz"; do
  check "12 compensate ${f%%|*}: named by its own flag" 2 "${f#*|}" "$B" compensate ${f%%|*} --out r12
done
sed 's/^coil_turns = .*/coil_turns = 9007199254740993/' "$SRC/models/single_rod.toml" >big12.toml
check "12 an integer beyond 2^53 in a model: quoted, not NaN" 2 \
  "big12.toml:[0-9]+: circuit.branches.coil.coil_turns = 9007199254740993: an integer beyond 2\^53" "$B" model check big12.toml
check "12 synthesize --periods: one range, stated whole" 2 \
  "periods \(--periods\) = 1e\+308: must be in \[1.5, 1e\+06\]" \
  "$B" identify synthesize --out r12 --periods 1e308 --temperatures 20 --currents 8 --frequencies 10
check "12 ablate: a diverged full model names its point, then its diagnosis" 3 \
  "ablate: the full model at 70 degC, 10 Hz diverged: diverged at t = .* H \[A/m\]" \
  "$B" ablate --model "$SRC/models/single_rod.toml" --set circuit.branches.coil.coil_turns=1e20 \
  --frequencies 10 --periods 1 --out r12
mkdir -p syn400 && cp syn/manifest.toml syn400/ && for f in syn/*.csv; do
  sed 's/^# temperature_C = .*/# temperature_C = 400/' "$f" >"syn400/$(basename "$f")"; done
check "12 identify: a record's temperature beyond the computable range, at its line" 2 \
  "syn400/T20_I8_f10.csv:[0-9]+: temperature 400 degC: outside the range" \
  "$B" "${ID[@]}" --data syn400/manifest.toml --fit fit.toml --out o12.toml
ok "12 ... and identify's report directory is not left behind" test ! -e o12_report
ok "12 ... and nothing written by the refused runs" test ! -e r12

echo "$pass passed, $fail failed"
[[ $fail -eq 0 ]]
