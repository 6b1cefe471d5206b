#!/usr/bin/env bash
# The MPI path: mpirun -np 2 (one archipelago per rank, champions on a ring of ranks, the
# refinement's Jacobian spread over the ranks) on the synthetic case; rank 0 writes the same
# outputs as a single process. Usage: identify_mpi.sh GMASIM WORK_DIR MPIEXEC
source "$(dirname "$0")/identify_common.sh"
MPIEXEC="$3"
# Containers: no CMA single-copy, allow root, allow 2 ranks on fewer cores.
export OMPI_MCA_btl_vader_single_copy_mechanism=none
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$MPIEXEC" -np 2 --oversubscribe "$GMASIM" "${COMMON[@]}" --generations 10 \
  --out mpi/model.toml >stdout.txt 2>stderr.txt || { cat stdout.txt stderr.txt; exit 1; }
cat stdout.txt
"$PY" "$SRC/tests/cli/check_identify.py" mpi/model_report/fit_report.json --gmasim "$GMASIM" --truth-model "$TRUTH" \
  --ranks 2
"$GMASIM" model check mpi/model.toml
for f in fit_report.md fit_report.json convergence.csv overlay_T70_I8_f100.csv; do
  [[ -s mpi/model_report/$f ]] || { echo "FAIL: missing mpi/model_report/$f"; exit 1; }
done
[[ $(grep -c "gmasim identify: generation" stderr.txt) -ge 2 ]]  # progress from rank 0 only
echo "PASS"
