#!/usr/bin/env bash
# The test suite on a busy machine: README command 2 (scripts/test.sh) RUNS times in a row
# (default 3) while LOAD busy processes (default 2, one per core here) keep the CPUs full, as
# other work does on CI and on a user's machine. Every run must pass: no test may depend on
# timing or on an idle machine. Extra arguments go to test.sh (and so to ctest).
# Prints each run's result and time, and exits non-zero when any run failed.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
runs="${RUNS:-3}"
load="${LOAD:-2}"
build_dir="${BUILD_DIR:-$root/build}"
mkdir -p "$build_dir"
# Built first, without the load: the load is for the tests.
bash "$root/scripts/build.sh"
busy=()
stop_load() {
  if [ ${#busy[@]} -gt 0 ]; then kill "${busy[@]}" 2>/dev/null || true; fi
  wait 2>/dev/null || true
}
trap stop_load EXIT
for ((i = 0; i < load; i++)); do
  (while :; do :; done) &
  busy+=("$!")
done
echo "test-under-load: $load busy processes started (pids ${busy[*]})"
failed=0
for ((run = 1; run <= runs; run++)); do
  start=$SECONDS
  log="$build_dir/test-under-load-$run.log"
  status=0
  bash "$root/scripts/test.sh" "$@" >"$log" 2>&1 || status=$?
  summary=$(grep -E "tests passed|tests failed" "$log" | tail -n 1 || true)
  echo "test-under-load: run $run of $runs: exit $status in $((SECONDS - start)) s: ${summary:-no ctest summary} ($log)"
  if [ "$status" -ne 0 ]; then
    failed=$((failed + 1))
    grep -A 40 "The following tests FAILED" "$log" || tail -n 40 "$log"
  fi
done
if [ "$failed" -ne 0 ]; then
  echo "test-under-load: $failed of $runs runs failed" >&2
  exit 1
fi
echo "test-under-load: all $runs runs passed under load"
