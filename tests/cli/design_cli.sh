#!/usr/bin/env bash
# gmasim design from the command line (issue 39, item 3): the same front on 1 thread, 2 threads
# and 2 MPI ranks; a search stopped after 2 generations and resumed to 4 equals the 4-generation
# search; refused inputs name the flag; sweep --grid on 2 ranks equals one process. Usage: design_cli.sh GMASIM WORK_DIR [MPIEXEC]
set -euo pipefail
GMASIM="$1"
WORK="$2"
MPIEXEC="${3:-}"
SRC="$(cd "$(dirname "$0")/../.." && pwd)"
rm -rf "$WORK"
mkdir -p "$WORK"
cd "$WORK"
PROBLEM=(design --variable preload.force_N=950:3000 --variable drive.current_pp_A=4:12
         --maximize stroke_um@20 --minimize coil_copper_loss_W@20
         --constraint 'temperature_rise_K@20<=25' --population 8)
same() {  # the two directories' design CSVs are byte for byte the same
  for f in design.csv design_population.csv; do
    cmp "$1/$f" "$2/$f" || { echo "FAIL: $1/$f differs from $2/$f"; diff "$1/$f" "$2/$f" | head; exit 1; }
  done
}
"$GMASIM" "${PROBLEM[@]}" --generations 4 --threads 1 --out one >one.txt
"$GMASIM" "${PROBLEM[@]}" --generations 4 --threads 2 --out two >/dev/null
same one two
grep -q "feasible designs on the Pareto front" one.txt
[[ $(wc -l <one/design_population.csv) -eq 9 ]]  # the header and 8 designs

# Stopped and resumed: the uninterrupted search, bit for bit.
"$GMASIM" "${PROBLEM[@]}" --generations 2 --checkpoint ck.txt --out half >/dev/null
"$GMASIM" "${PROBLEM[@]}" --generations 4 --checkpoint ck.txt --resume --out resumed >resumed.txt
grep -q "resumed at generation 2" resumed.txt
same one resumed
# Another problem is refused with the checkpoint's name; so is a damaged one.
set +e
"$GMASIM" "${PROBLEM[@]}" --generations 4 --seed 9 --checkpoint ck.txt --resume --out bad 2>err.txt
rc=$?
set -e
[[ $rc -eq 2 ]] && grep -q "ck.txt.*cannot resume" err.txt || { echo "FAIL: seed change"; cat err.txt; exit 1; }
head -c 300 ck.txt >cut.txt
set +e
"$GMASIM" "${PROBLEM[@]}" --generations 4 --checkpoint cut.txt --resume --out bad 2>err.txt
rc=$?
set -e
[[ $rc -eq 2 ]] && grep -q "damaged checkpoint" err.txt || { echo "FAIL: damaged"; cat err.txt; exit 1; }

# Refused inputs name the flag and the rule.
refused() {  # expected exit code, expected text, arguments...
  local code="$1" text="$2"
  shift 2
  set +e
  "$GMASIM" "$@" --out refused >/dev/null 2>err.txt
  local rc=$?
  set -e
  [[ $rc -eq $code ]] && grep -q -- "$text" err.txt || {
    echo "FAIL: $* -> $rc (expected $code, '$text')"; cat err.txt; exit 1; }
}
refused 2 "unknown quantity 'strok_um'" design --variable preload.force_N=950:3000 \
  --maximize strok_um@20 --minimize rods_mass_kg
refused 2 "give two or more" design --variable preload.force_N=950:3000 --maximize stroke_um@20
refused 2 "expected KEY=LOWER:UPPER" design --variable preload.force_N \
  --maximize stroke_um@20 --minimize rods_mass_kg
refused 2 "must be a multiple of 4" design --variable preload.force_N=950:3000 \
  --maximize stroke_um@20 --minimize rods_mass_kg --population 10
refused 2 "expected QUANTITY<=BOUND" design --variable preload.force_N=950:3000 \
  --maximize stroke_um@20 --minimize rods_mass_kg --constraint 'rods_mass_kg<0.1'
cp "$SRC/models/single_rod.toml" mine.toml
refused 2 "checkpoint" design --model mine.toml --variable rod.length_m=0.03:0.08 \
  --maximize stroke_um@20 --minimize rods_mass_kg --current-min 0 --checkpoint mine.toml
cmp mine.toml "$SRC/models/single_rod.toml"  # the model file is untouched
refused 1 "requires --checkpoint\|--resume requires" design --variable preload.force_N=950:3000 \
  --maximize stroke_um@20 --minimize rods_mass_kg --resume

# The design study of sweep --grid, whose designs the MPI ranks share below.
GRID=(sweep --model single_rod --current-min 0 --currents 4 --temperatures 20,70
      --grid rod.length_m=0.05,0.06,0.08 --grid circuit.branches.coil.coil_turns=500,800)
"$GMASIM" "${GRID[@]}" --out grid_one >/dev/null

if [[ -n "$MPIEXEC" ]]; then
  # Containers: no CMA single-copy, allow root, allow 2 ranks on fewer cores.
  export OMPI_MCA_btl_vader_single_copy_mechanism=none
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  "$MPIEXEC" -np 2 --oversubscribe "$GMASIM" "${PROBLEM[@]}" --generations 4 --threads 1 --out mpi \
    >mpi.txt 2>mpi_err.txt || { cat mpi.txt mpi_err.txt; exit 1; }
  grep -q "on 2 rank(s)" mpi.txt || { echo "FAIL: not 2 ranks"; cat mpi.txt; exit 1; }
  same one mpi
  "$MPIEXEC" -np 2 --oversubscribe "$GMASIM" "${GRID[@]}" --out grid_mpi >grid_mpi.txt 2>&1 ||
    { cat grid_mpi.txt; exit 1; }
  grep -q "6 designs x 2 points on 2 rank(s)" grid_mpi.txt || { cat grid_mpi.txt; exit 1; }
  for f in sweep.csv sweep_designs.csv; do
    cmp "grid_one/$f" "grid_mpi/$f" || { echo "FAIL: sweep --grid on 2 ranks: $f differs"; exit 1; }
  done
  # A sweep without --grid has nothing to share: refused under mpirun, naming --grid.
  set +e
  "$MPIEXEC" -np 2 --oversubscribe "$GMASIM" sweep --temperatures 20 --currents 8 --out plain \
    >plain.txt 2>&1
  rc=$?
  set -e
  [[ $rc -ne 0 ]] && grep -q "MPI ranks share the designs of --grid" plain.txt ||
    { echo "FAIL: plain sweep under mpirun"; cat plain.txt; exit 1; }
fi
echo "PASS"
