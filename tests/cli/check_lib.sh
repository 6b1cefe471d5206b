# Shared by the CLI test scripts (source it): pass/fail counters and the check helpers.
pass=0
fail=0
check() {  # name, expected exit code, expected text (grep -E) in stdout+stderr, command...
  local name="$1" code="$2" text="$3"
  shift 3
  local out rc
  out="$(timeout 300 "$@" 2>&1)"
  rc=$?
  if [[ $rc -eq $code ]] && grep -qE -- "$text" <<<"$out"; then
    pass=$((pass + 1))
  else
    fail=$((fail + 1))
    echo "FAIL: $name (exit $rc, expected $code; wanted /$text/)"
    echo "$out" | head -c 600
    echo
  fi
}
ok() {  # name, command: passes if the command succeeds
  local name="$1"
  shift
  if "$@"; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAIL: $name"; fi
}
