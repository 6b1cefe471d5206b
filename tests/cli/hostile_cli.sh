#!/usr/bin/env bash
# Regression tests of issue 8 (hostile input): each defect found by the mutation campaign is
# a check here, numbered as in the issue. Every hostile input must give a clear error and
# the documented exit code (1 usage, 2 bad input), never a crash (>= 128), a hang (timeout
# 124), or exit 0 with nonsense. Usage: hostile_cli.sh <path to gmasim>.
set -u
B="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
SRC="$(cd "$(dirname "$0")/../.." && pwd)"
T="$(mktemp -d)"
trap 'rm -rf "$T"' EXIT
cd "$T"
source "$SRC/tests/cli/check_lib.sh"

# ---- 1. checkpoints are not trusted --------------------------------------------------
cat >fit.toml <<'EOF'
[[parameter]]
name = "material.lambda_s"
lower = 0.8e-3
upper = 1.2e-3

[[target]]
kind = "stroke_change_pct"
temperature_C = 70.0
current_pp_A = 8.0
frequency_Hz = 10.0
value = -12.6

[[target]]
kind = "hysteresis_change_pct"
temperature_C = 70.0
current_pp_A = 8.0
frequency_Hz = 10.0
value = -27.6
EOF
ID=(identify --fit fit.toml --islands 1 --population 8 --migrate-every 1 --no-refine --no-plots
    --quiet --steps-per-period 100 --threads 1)
check "identify writes a checkpoint" 0 "" "$B" "${ID[@]}" --out m.toml --generations 2 \
  --checkpoint ck.txt --checkpoint-every 1
R=("$B" "${ID[@]}" --out m2.toml --generations 3 --resume)
check "resume an honest checkpoint" 0 "" "${R[@]}" ck.txt
# A checkpoint edited by a sed script must be refused with the message.
forged() {  # name, sed script, expected message (grep -E)
  sed "$2" ck.txt >"forged.txt"
  check "1 $1" 2 "$3" "${R[@]}" forged.txt
}
forged "island of size 0" 's/ size 8$/ size 0/' "island 0 has 0 individuals; the population is 8"
forged "best_f -1" 's/^best_f .*/best_f -1/' "best_f -1: must be finite and >= 0"
forged "best_f -inf" 's/^best_f .*/best_f -inf/' "best_f -inf: must be finite"
forged "point outside the bounds" 's/^best_u .*/best_u 7.5/' "coordinate 7.5 is outside \[0, 1\]"
forged "population 0" 's/^population 8$/population 0/' "population 0: must be an integer in"
forged "version 1e88 (fuzz_checkpoint: float-to-int overflow)" '1s/.*/gmasim-identify-checkpoint 1e88/' \
  "version 1e\+88 is not supported"
forged "history step 1e88" 's/^ga 1 /ga 1e88 /' "history: step 1e\+88 / evaluations .*: not a count in range"
forged "islands 1e18" 's/^islands 1$/islands 1e18/' "islands 1e\+18: must be an integer"
# Forge the last individual's fitness: it would become the champion.
awk 'BEGIN{n=0} /^island /{isl=1} {if (isl && $0 ~ /^[0-9.e+-]+ [0-9.e+-]+$/) {n++; if (n==8) {$1="0.005"}} print}' ck.txt >c_forged.txt
check "1 forged fitness" 2 "stored fitness value\(s\) are not what the model gives" "${R[@]}" c_forged.txt

# ---- 2, 3. identify counts -----------------------------------------------------------
check "2 --target-periods 1e18" 2 "target periods = 1e\+18: must be in \[1, 10000\]" \
  "$B" "${ID[@]}" --out m3.toml --generations 1 --target-periods 1e18
check "3 --steps-per-period 1e20" 2 "steps per period = 1e\+20: must be in \[8, 1e\+06\]" \
  "$B" identify --fit fit.toml --out m3.toml --population 8 --generations 1 --no-plots --quiet \
  --steps-per-period 1e20
mkdir -p d
{
  echo "# temperature_C = 20"
  echo "# frequency_Hz = 1e300"
  echo "# current_pp_A = 8"
  echo "t_s,current_A,displacement_um"
  for k in 0 1 2 3 4 5 6 7 8 9; do echo "0.0$k,$k,$k"; done
} >d/huge_f.csv
printf '[[measurement]]\nfile = "huge_f.csv"\n' >d/manifest.toml
check "3 frequency_Hz 1e300 in data" 2 "frequency_Hz = 1e\+300: must be in \(0, 1e\+06\] Hz" \
  "$B" identify --data d/manifest.toml --fit 'material.lambda_s:0.8e-3:1.2e-3' --out m4.toml \
  --population 8 --generations 1 --no-plots --quiet

# ---- 4. extreme weights -----------------------------------------------------------------
{
  echo "# temperature_C = 20"
  echo "t_s,current_A,displacement_um"
  for k in 0 1 2 3 4 5 6 7 8 9; do echo "0.00$k,$k,$k"; done
} >d/dc.csv
printf '[[measurement]]\nfile = "dc.csv"\nweight = 1e308\n' >d/heavy.toml
check "4 manifest weight 1e308" 2 "weight = 1e\+308: must be in \[1e-6, 1e6\]" \
  "$B" identify --data d/heavy.toml --fit 'material.lambda_s:0.8e-3:1.2e-3' --out m5.toml \
  --population 8 --generations 1 --no-plots --quiet

# ---- 5. simulate step counts ---------------------------------------------------------------
check "5 --periods 1e300" 2 "periods \(--periods\) = 1e\+300: must be in \[1, 1e\+06\]" "$B" simulate --periods 1e300 --out s
check "5 --periods inf" 1 "--periods inf: must be a finite number" "$B" simulate --periods inf --out s
check "5 --frequency 1e-300" 2 "steps per period = .*too many" "$B" simulate --frequency 1e-300 --out s
# Issue 19, item 2: a step below 1e-12 s is refused before it becomes a count.
check "5 --dt 1e-300" 2 "dt = 1e-300 s \(--dt, dt_s\): must be in \[1e-12, 0.001\] s" "$B" simulate --dt 1e-300 --out s
check "5 --duration inf" 1 "--duration inf: must be a finite number" "$B" simulate --duration inf --out s
check "5 chirp --f1 inf" 1 "--f1 inf: must be a finite number" "$B" simulate --waveform-kind chirp --f1 inf --out s
check "5 chirp --f1 1e300" 2 "chirp end frequency = 1e\+300 Hz: must be in" "$B" simulate --waveform-kind chirp --f1 1e300 --duration 1 --out s
printf 't_s,current_A\n0,1\n1e300,2\n' >w_long.csv
check "5 waveform ending at 1e300 s" 2 "steps of 1e-05 s over 1e\+300 s: too many" "$B" simulate --waveform w_long.csv --out s
check "5 record too long" 2 "rows \(limit 2e\+07\); record less often" "$B" simulate --periods 3000 --out s
ok "5 no output after a refused run" test ! -e s/timeseries.csv

# ---- 6, 7. lists -------------------------------------------------------------------------
check "6 range step 1e-300" 2 "range 30:1e-300:70 has .* values \(limit 100000\)" \
  "$B" sweep --temperatures 20,30:1e-300:70 --periods 1 --out sw
check "7 track --amplitudes 1e300" 2 "reference amplitude \(--amplitudes\) = 1e\+300 um: must be in \[0 um, 10000 um\]" \
  "$B" track --amplitudes 1e300 --temperatures 20 --out tr
ok "7 no track.csv after a refused run" test ! -e tr/track.csv

# ---- 8. non-finite flags and model values --------------------------------------------------
check "8 --step-time nan" 1 "--step-time nan: must be a finite number" "$B" simulate --step-time nan --out s
check "8 --temperature nan" 1 "--temperature nan: must be a finite number" "$B" simulate --temperature nan --out s
sed '0,/^k_j = 1.07 /s//k_j = 1e-320 /' "$SRC/models/mdma.toml" >kj.toml
check "8 k_j = 1e-320" 2 "kj.toml:[0-9]+: rod1.k_j = .*: outside the range of any physical value" "$B" model check kj.toml

# ---- 9. size limits ---------------------------------------------------------------------
check "9 model check /dev/zero" 2 "larger than 256 MiB" "$B" model check /dev/zero
check "9 --resume /dev/zero" 2 "checkpoint is larger than 256 MiB" "${R[@]}" /dev/zero
check "9 frf --points 2e9" 2 "frequency points \(--points\) = 2e\+09: too many \(limit 100000\)" "$B" frf --points 2000000000 --out f
printf 't_s,current_A\n100,1\n100.01,2\n' >w_late.csv
check "9 waveform starting at t = 100 s" 2 "starts at t = 100 s; a waveform table must start at t = 0" \
  "$B" simulate --waveform w_late.csv --out s

# ---- 10. non-regular destinations ---------------------------------------------------------
mkdir -p dev
ln -s /dev/null dev/metrics.json
check "10 a device at the destination" 2 "the destination is a character device" "$B" simulate --periods 1 --out dev
ok "10 /dev/null is still a device" test -c /dev/null
ok "10 nothing written beside it" test ! -e dev/timeseries.csv

# ---- 11. evaluation errors stop the run -------------------------------------------------
{
  echo "# temperature_C = 20"
  echo "t_s,current_A,displacement_um"
  echo "0,0,0"
  echo "1000,1,1"
  echo "2000,2,2"
  echo "3000,1,3"
  echo "4000,0,2"
} >d/undated.csv
printf '[[measurement]]\nfile = "undated.csv"\n' >d/m_undated.toml
check "11 undated record without --dt" 2 "steps of 1e-05 s over the record's 4000 s: too many .* give --dt" \
  "$B" identify --data d/m_undated.toml --fit 'material.lambda_s:0.8e-3:1.2e-3' --out m6.toml \
  --population 8 --generations 1 --no-plots --quiet
sed 's/^coil_turns = 720.0 /coil_turns = 7.2e9 /' "$SRC/models/mdma.toml" >start_div.toml
check "11 a start model that diverges stops the run" 2 "the start model start_div.toml \(--model\) cannot be evaluated on the data and targets \(--data, --fit\): diverged" \
  "$B" "${ID[@]}" --model start_div.toml --out m7.toml --generations 1

# ---- 12. simulate writes one set ---------------------------------------------------------
check "12 simulate" 0 "wrote" "$B" simulate --periods 1 --out pair
ok "12 metrics.json names its timeseries.csv" /usr/bin/python3 - pair <<'EOF'
import json, sys, pathlib
d = pathlib.Path(sys.argv[1])
data = (d / "timeseries.csv").read_bytes()
h = 14695981039346656037
for c in data:
    h = ((h ^ c) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
m = json.loads((d / "metrics.json").read_text())["timeseries_csv"]
sys.exit(0 if m == {"bytes": len(data), "fnv1a64": f"{h:016x}"} else 1)
EOF
ok "12 no temporary left" test -z "$(ls pair | grep tmp)"

# ---- 13. parse errors ---------------------------------------------------------------------
# Issue 19, item 11: the unknown flag is named with a suggestion, a bad number with its unit.
check "13 unknown flag is a usage error" 1 "unknown flag --bogus" "$B" simulate --bogus
check "13 bad number is a usage error" 1 "--periods 'abc': not a number" "$B" simulate --periods abc
check "13 +-1" 1 "--periods '\+-1': not a number" "$B" simulate --periods +-1
printf 't_s,current_A\n0,1\n0.001,+-1\n' >w_sign.csv
check "13 +-1 in a CSV cell" 2 "w_sign.csv:3: non-numeric cell '\+-1'" "$B" simulate --waveform w_sign.csv --out s
check "13 +-1 in a list" 2 "'\+-1' is not a finite number" "$B" sweep --temperatures 20,+-1 --out sw
# One argument may hold at most 128 KiB (Linux MAX_ARG_STRLEN): 100 kB.
long="$(head -c 100000 /dev/zero | tr '\0' '7')x"
out="$("$B" simulate --periods "$long" 2>&1)"
rc=$?
ok "13 a 100 kB value: usage error" test "$rc" -eq 1
ok "13 a 100 kB value is not echoed whole (${#out} characters)" test "${#out}" -lt 5000
big="$(head -c 1000000 /dev/zero | tr '\0' '7')x"
printf 't_s,current_A\n0,1\n0.001,%s\n' "$big" >w_big.csv
out="$("$B" simulate --waveform w_big.csv --out s 2>&1)"
rc=$?
ok "13 a 1 MB cell: bad input" test "$rc" -eq 2
ok "13 a 1 MB cell is not echoed whole (${#out} characters)" test "${#out}" -lt 5000

# ---- 14. inputs toml++ 3.3 mishandles (asserts / UB upstream) -----------------------------
for hdr in '[[[1]]]' '[[[a]]' '[[[]]' '[[=' '[&' '[Π]'; do
  printf '%s\nx = 1\n' "$hdr" >bad_header.toml
  check "14 header $hdr (model)" 2 "bad_header.toml:1: malformed table header" "$B" model check bad_header.toml
  check "14 header $hdr (fit spec)" 2 "bad_header.toml:1: malformed table header" \
    "$B" identify --fit bad_header.toml --out m8.toml --population 8 --generations 1 --no-plots --quiet
done
printf 'Π = 1\n' >bad_key.toml
check "14 U+03A0 key" 2 "bad_key.toml:1: expected a key" "$B" model check bad_key.toml
printf '[meta]\nname = "a\0b"\n' >nul.toml
check "14 NUL byte" 2 "nul.toml:2: NUL byte" "$B" model check nul.toml

# ---- issue 9 item 7: the new record formats and their options -------------------------
SYN=(identify synthesize --temperatures 20 --currents 8 --frequencies 10 --no-flux)
check "precycles < 0" 2 "precycles -1: must be in \[0, 100\]" "$B" "${SYN[@]}" --out sy1 --precycles -1
check "precycles huge" 1 "--precycles '1e30': not a whole number" "$B" "${SYN[@]}" --out sy2 --precycles 1e30
check "response offset inf" 1 "must be a finite number" "$B" "${SYN[@]}" --out sy3 --response-offset inf
check "unknown drive" 1 "bogus not in" "$B" "${SYN[@]}" --out sy4 --drive bogus
check "rod not in the model" 2 "rod = 'nope' is not a rod of the model" "$B" "${SYN[@]}" --out sy5 --drive field --rod nope
printf '# temperature_C = 20\n# offset = fitted\nfield_A_per_m,strain_ppm\n0,0\n1e3,5\n2e3,20\n1e3,6\n0,1\n' >qs.csv
printf '[[measurement]]\nfile = "qs.csv"\n' >qs_manifest.toml
QS=(identify --data qs_manifest.toml --fit fit.toml --out q.toml --islands 1 --population 8
    --generations 1 --no-refine --no-plots --quiet --threads 1)
check "quasi-static increments nan" 1 "must be a finite number" "$B" "${QS[@]}" --quasi-static-increments nan
check "quasi-static increments 1e300" 2 "quasi-static increments per range" "$B" "${QS[@]}" --quasi-static-increments 1e300
check "quasi-static increments 0" 2 "quasi-static increments per range" "$B" "${QS[@]}" --quasi-static-increments 0
check "a quasi-static field loop fits" 0 "" "$B" "${QS[@]}"

# ---- issue 41: the last hostile cases ----------------------------------------------------
# A model whose circuit carries no coil is refused where it is, not run with stroke 0.
sed 's/^coil_turns = 500.0.*/coil_turns = 0.0/' "$SRC/models/single_rod.toml" >no_coil.toml
check "41 no coil in the circuit" 2 "no_coil.toml:[0-9]+: no circuit branch carries a coil" \
  "$B" model check no_coil.toml
check "41 --param with two colons names the form" 2 "--param material.Ms_A_per_m:1:2: expected NAME or NAME:SCALE" \
  "$B" sensitivity --param material.Ms_A_per_m:1:2 --out sens41
check "41 --set of a text key says it is text" 2 "meta.name is text, not a parameter" \
  "$B" model save --set 'meta.name=q" # [x]' --out ms41.toml
check "41 --set of a number with a word" 2 "material.Ms_A_per_m takes a number; the value 'big' is not a finite number" \
  "$B" model save --set material.Ms_A_per_m=big --out ms41.toml
check "41 --set of an unknown key with a word" 2 "unknown parameter 'material.colour'" \
  "$B" model save --set material.colour=red --out ms41.toml
printf 't_s,current_A\n0,0\n1e-320,1\n' >w_tiny.csv
check "41 a waveform shorter than a step blames the file" 2 "w_tiny.csv: the waveform spans .* shorter than one time step" \
  "$B" simulate --waveform w_tiny.csv --out s41
cat >fit_old_names.toml <<'TOML'
[[parameter]]
name = "rod1.ja.k0"
lower = 1000
upper = 5000
[[parameter]]
name = "material.Ms"
lower = 5e5
upper = 9e5
[[parameter]]
name = "material.chi_m"
lower = 8
upper = 50
[[target]]
kind = "stroke_um"
temperature_C = 20
current_pp_A = 8
current_min_A = -3
frequency_Hz = 10
value = 50
TOML
OLD=("$B" identify --fit fit_old_names.toml --out old.toml --islands 1 --population 8 --generations 1 --no-plots --quiet)
check "41 every old unit-less fit name reported (count)" 2 "2 of the fit's 3 parameter names are not the model's" "${OLD[@]}"
check "41 every old unit-less fit name reported (first)" 2 "fit_old_names.toml:1: .*write 'rod1.ja.k0_A_per_m'" "${OLD[@]}"
check "41 every old unit-less fit name reported (second)" 2 "fit_old_names.toml:5: .*write 'material.Ms_A_per_m'" "${OLD[@]}"

# ---- issue 39 item 3: design studies ----------------------------------------------------
GRID=("$B" sweep --model single_rod --current-min 0 --currents 4 --temperatures 20 --periods 2)
check "39 sweep --grid runs two designs" 0 "design rod.length_m=0.08: rods 0.0" \
  "${GRID[@]}" --grid rod.length_m=0.05,0.08 --out grid1
ok "39 sweep --grid writes one row per design" test "$(wc -l <grid1/sweep_designs.csv)" -eq 3
ok "39 sweep --grid puts the key beside every point" grep -q "^rod.length_m," grid1/sweep.csv
check "39 --grid of an unknown key names it" 2 "--grid rod.colour_m: " \
  "${GRID[@]}" --grid rod.colour_m=1,2 --out grid2
check "39 --grid of a value the key refuses" 2 "--grid rod.length_m=-0.01: " \
  "${GRID[@]}" --grid rod.length_m=0.05,-0.01 --out grid3
check "39 --grid without values" 2 "--grid 'rod.length_m': expected KEY=v1,v2" \
  "${GRID[@]}" --grid rod.length_m --out grid4

echo "$pass passed, $fail failed"
[[ $fail -eq 0 ]]
