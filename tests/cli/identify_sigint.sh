#!/usr/bin/env bash
# SIGINT stops cleanly: the best model so far, a report and a checkpoint are written, the
# exit status is 130, and the checkpoint resumes. Usage: identify_sigint.sh GMASIM WORK_DIR
source "$(dirname "$0")/identify_common.sh"

"$GMASIM" "${COMMON[@]}" --generations 500 --checkpoint ck.txt --checkpoint-every 5 \
  --out stopped/model.toml 2>stderr.txt &
PID=$!
for _ in $(seq 1 1200); do
  if [[ -f ck.txt ]]; then break; fi
  sleep 0.05
done
kill -INT "$PID"
set +e
wait "$PID"
rc=$?
set -e
[[ $rc -eq 130 ]] || { cat stderr.txt; echo "FAIL: exit status $rc after SIGINT, expected 130"; exit 1; }
grep -q "interrupted: wrote the best model so far" stderr.txt
grep -q "gmasim identify: generation" stderr.txt  # progress on stderr
"$GMASIM" model check stopped/model.toml
"$PY" "$SRC/tests/cli/check_identify.py" stopped/model_report/fit_report.json --gmasim "$GMASIM" --truth-model "$TRUTH" \
  --interrupted --max-rms 100
BEST=$(awk '$1 == "best_f" {print $2}' ck.txt)
GEN=$(awk '$1 == "generation" {print $2}' ck.txt)
"$GMASIM" "${COMMON[@]}" --generations $((GEN + 5)) --checkpoint ck.txt --out resumed/model.toml \
  --resume ck.txt --no-refine --no-profile --quiet
"$PY" "$SRC/tests/cli/check_identify.py" resumed/model_report/fit_report.json --gmasim "$GMASIM" --truth-model "$TRUTH" \
  --resumed --not-worse-than "$BEST" --max-rms 100 --skip-params
echo "PASS"
