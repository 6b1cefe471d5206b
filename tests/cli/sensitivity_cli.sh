#!/usr/bin/env bash
# gmasim sensitivity end to end: outputs, stdout JSON, flags checked by name, no output over
# an input, --fit, the figure. Usage: sensitivity_cli.sh <path to gmasim>
set -u
B="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
T="$(mktemp -d)"
trap 'rm -rf "$T"' EXIT
source "$(dirname "$0")/check_lib.sh"
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
S="$B sensitivity"
# Eq. 21 only (no simulation): the files, the long CSV, the analytic derivative in the JSON.
check "files" 0 "wrote $T/a/sensitivity.csv, $T/a/sensitivity.json, $T/a/identifiability.json" \
  $S --param thermal_expansion.sleeve_length_m --param material.alpha_thermal_per_K \
  --claim thermal_model --claim thermal_measured --out "$T/a"
ok "csv header" grep -q '^quantity,quantity_unit,kind,quantity_value,quantity_scale,parameter,parameter_unit,parameter_value,step,derivative_unit,derivative_h_large,derivative_h_small' "$T/a/sensitivity.csv"
ok "csv rows" test "$(wc -l <"$T/a/sensitivity.csv")" -eq 5
ok "absolute step unit" grep -qE 'thermal_model,.*,thermal_expansion.sleeve_length_m,m,0.05171,absolute,um/degC/\(m\),-17.(2|19999)' "$T/a/sensitivity.csv"
ok "identifiability.json" grep -q '"combination": ' "$T/a/identifiability.json"
ls "$T/a" | grep -q tmp && { fail=$((fail + 1)); echo "FAIL: temp files left"; } || pass=$((pass + 1))
# --json - : the JSON on stdout, the summary on stderr, no directory.
out="$(cd "$T" && $S --param thermal_expansion.sleeve_length_m --claim thermal_model --json - 2>/dev/null)"
grep -qE '"derivative": -17.(2|19999)' <<<"$out" && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: stdout json"; }
[[ ! -e "$T/out" ]] && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: --json - wrote out/"; }
# A simulated claim and a metric quantity, with the summary's table and identifiability.
check "simulated" 0 "stroke_drop_8A .* material.Ms_A_per_m -[0-9]" $S --param material.Ms_A_per_m \
  --claim stroke_drop_8A --claim 'stroke_um@20C_8A_10Hz' --threads 2 --out "$T/b"
# Every numeric flag checked, by name.
check "step order" 2 "--step-small 0.02: must be below --step-large 0.01" $S --param material.Ms_A_per_m --step-small 0.02 --out "$T/c"
check "step range" 2 "--step-large 0.7: must be in \(0, 0.5\)" $S --param material.Ms_A_per_m --step-large 0.7 --out "$T/c"
check "agreement" 2 "--agreement -1: must be in" $S --param material.Ms_A_per_m --agreement -1 --out "$T/c"
check "near-null" 2 "--near-null 2: must be in" $S --param material.Ms_A_per_m --near-null 2 --out "$T/c"
check "floor" 2 "--floor 1: must be in \[0, 1\)" $S --param material.Ms_A_per_m --floor 1 --out "$T/c"
check "threads" 2 "--threads -2: must be in \[0, 4096\]" $S --param material.Ms_A_per_m --threads -2 --out "$T/c"
check "nan flag" 1 "--step-large nan: must be a finite number" $S --param material.Ms_A_per_m --step-large nan --out "$T/c"
check "param scale" 2 "--param rod3.inner_diameter_m:abc: the scale after ':' must be a finite number > 0" $S --param rod3.inner_diameter_m:abc --out "$T/c"
check "zero without scale" 2 "rod3.inner_diameter_m = 0 m .*needs a scale" $S --param rod3.inner_diameter_m --out "$T/c"
check "refused step" 0 "step_refused" $S --param rod3.inner_diameter_m:0.001 --claim thermal_model --out "$T/c"
check "unknown param" 2 "unknown parameter 'nope'" $S --param nope --out "$T/c"
check "unknown claim" 2 "unknown quantity 'nope'" $S --param material.Ms_A_per_m --claim nope --out "$T/c"
check "no param" 2 "no parameter: give --param" $S --out "$T/c"
check "one stdout" 2 "only one of them can go to standard output" $S --param material.Ms_A_per_m --json - --csv -
check "plot needs out" 2 "--plot draws into --out DIR" $S --param material.Ms_A_per_m --json - --plot
# No output over an input.
cp "$ROOT/models/mdma.toml" "$T/m.toml"
check "json over model" 2 "would overwrite the input file" $S --model "$T/m.toml" --param material.Ms_A_per_m --claim thermal_model --json "$T/m.toml"
printf '[[parameter]]\nname = "material.Ms_A_per_m"\nlower = 6e5\nupper = 8e5\n' >"$T/sensitivity.json"
check "out over fit" 2 "would overwrite the input file" $S --fit "$T/sensitivity.json" --claim thermal_model --out "$T"
cmp -s "$T/m.toml" "$ROOT/models/mdma.toml" && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL: input changed"; }
# --fit: the fit spec's parameters (an absolute step at 0 takes the bounds' width).
printf '[[parameter]]\nname = "magnet.alpha_pm1_per_K"\nlower = -3e-4\nupper = 0.0\n[[parameter]]\nname = "material.x"\nlower = 0.3\nupper = 0.5\n' >"$T/fit0.toml"
check "fit spec" 0 "magnet.alpha_pm1_per_K .* d/d p, step h x 0.0003" $S --fit "$T/fit0.toml" --claim thermal_model --out "$T/f"
# The heatmap, through the Python package of this build (absent in the sanitize-native build).
if compgen -G "$(dirname "$B")/../python/gmasim/_gmasim*.so" >/dev/null; then
  check "plot" 0 "sensitivity.png" $S --param thermal_expansion.sleeve_length_m --param thermal_expansion.sleeve_alpha_per_K --param material.alpha_thermal_per_K --claim thermal_model --plot --out "$T/p"
  ok "png and svg" test -s "$T/p/sensitivity.png" -a -s "$T/p/sensitivity.svg"
else
  echo "skip: --plot (no Python module in this build)"
fi
echo "$pass passed, $fail failed"
[[ $fail -eq 0 ]]
