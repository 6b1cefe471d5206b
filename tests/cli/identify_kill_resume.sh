#!/usr/bin/env bash
# A run killed with SIGKILL and resumed from its checkpoint ends at least as good as the
# checkpoint's best. Usage: identify_kill_resume.sh GMASIM_BINARY WORK_DIR
source "$(dirname "$0")/identify_common.sh"

"$GMASIM" "${COMMON[@]}" --generations 500 --checkpoint ck.txt --checkpoint-every 5 \
  --out killed/model.toml --quiet &
PID=$!
for _ in $(seq 1 1200); do
  if [[ -f ck.txt ]] && grep -qE '^generation (1[0-9]|[2-9][0-9])$' ck.txt; then break; fi
  if ! kill -0 "$PID" 2>/dev/null; then echo "FAIL: the run ended before it was killed"; exit 1; fi
  sleep 0.05
done
kill -KILL "$PID"
set +e
wait "$PID"
rc=$?
set -e
[[ $rc -eq 137 ]] || { echo "FAIL: exit status $rc after SIGKILL, expected 137"; exit 1; }
[[ ! -e killed/model.toml ]] || { echo "FAIL: a killed run wrote a model"; exit 1; }
GEN=$(awk '$1 == "generation" {print $2}' ck.txt)
BEST=$(awk '$1 == "best_f" {print $2}' ck.txt)
echo "killed after the checkpoint of generation $GEN (best $BEST %)"

# Resume (the same command plus --resume; fewer total generations keep the test short).
# (--no-profile: the intervals are tested elsewhere; this test is about the resume.)
"$GMASIM" "${COMMON[@]}" --generations $((GEN + 10)) --checkpoint ck.txt --checkpoint-every 5 \
  --out resumed/model.toml --resume ck.txt --quiet --no-profile
"$PY" "$SRC/tests/cli/check_identify.py" resumed/model_report/fit_report.json --gmasim "$GMASIM" --truth-model "$TRUTH" \
  --resumed --not-worse-than "$BEST" --skip-params
"$GMASIM" model check resumed/model.toml
grep -q '^# command: gmasim identify .*--resume ck.txt' resumed/model.toml
echo "PASS"
