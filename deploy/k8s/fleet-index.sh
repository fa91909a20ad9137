#!/bin/sh
# One index of the fleet Job (deploy/k8s/fitcal-fleet-job.yaml), installed in the image as
# /usr/share/fitcal/fleet-index.sh. $FLEET_DIR/datasets.txt lists N data sets, one a line (paths
# relative to $FLEET_DIR, or absolute); the Job has N + 1 indexes:
#   index i < N  calibrates line i + 1: results/<data set>/<date>/cal.yaml, report/metrics.json,
#                fit.txt (what fit printed) and exit_status; exits with fit's status when fit
#                wrote nothing (5: refused), so that the Job marks that index, and only it, failed.
#   index N      waits until every robot index has left its status, then writes
#                summary/<date>.txt: each index's outcome and `fitcal fleet results` (every
#                date's calibrations); exits with fleet's status.
# Environment: JOB_COMPLETION_INDEX (set by Kubernetes), RUN_ID (the Job's uid: which statuses
# belong to this run), FLEET_DIR (default /fleet), RUN_DATE (default today, UTC), FLEET_WAIT_S
# (how long the summary waits for the others, default 6 h), FLEET_POLL_S (default 10).
# POSIX sh: the image runs it with busybox sh. No `set -e`: fitcal's exit statuses are results to
# record, not errors to stop at.
set -u

fleet=${FLEET_DIR:-/fleet}
index=${JOB_COMPLETION_INDEX:?JOB_COMPLETION_INDEX is set by Kubernetes for an Indexed Job}
run=${RUN_ID:?RUN_ID names this run: the Job sets it to its uid}
date=${RUN_DATE:-$(date -u +%F)}
list=$fleet/datasets.txt
status_dir=$fleet/runs/$run

fail() {
  echo "fleet-index.sh: $1" >&2
  exit 2
}

[ -r "$list" ] || fail "$list: cannot read the list of data sets"
robots=$(grep -c '' "$list")
mkdir -p "$status_dir" || fail "$status_dir: cannot create"

# Index < N: one robot. Whatever fitcal decides, the status file is written last, so the summary
# never reads a result that is still being written.
calibrate() {
  data=$(sed -n "$((index + 1))p" "$list")
  [ -n "$data" ] || fail "$list:$((index + 1)): empty line (one data set a line)"
  case $data in /*) ;; *) data=$fleet/$data ;; esac
  name=$(basename "$data")
  out=$fleet/results/$name/$date
  # A rerun on the same date replaces that date's result (and never keeps a stale calibration
  # beside a new refusal).
  rm -rf "$out"
  mkdir -p "$out" || fail "$out: cannot create"
  fitcal fit --logs "$data" --out "$out/cal.yaml" > "$out/fit.txt" 2>&1
  status=$?
  cat "$out/fit.txt"
  code=$status
  # 6: written with a warning (iteration limit). A written calibration gets its report.
  if [ "$status" -eq 0 ] || [ "$status" -eq 6 ]; then
    fitcal report --logs "$data" --calibration "$out/cal.yaml" --out "$out/report" \
      > "$out/report.txt" 2>&1
    code=$?
    cat "$out/report.txt"
  fi
  echo "$status" > "$out/exit_status"
  echo "$name $status" > "$status_dir/$index"
  exit "$code"
}

# Index N: the summary, once every robot index has left a status (or FLEET_WAIT_S has passed).
summarise() {
  waited=0
  while :; do
    missing=""
    i=0
    while [ "$i" -lt "$robots" ]; do
      [ -e "$status_dir/$i" ] || missing="$missing $i"
      i=$((i + 1))
    done
    [ -z "$missing" ] && break
    if [ "$waited" -ge "${FLEET_WAIT_S:-21600}" ]; then
      echo "fleet-index.sh: no status from index$missing after $waited s; summarising the rest" >&2
      break
    fi
    sleep "${FLEET_POLL_S:-10}"
    waited=$((waited + ${FLEET_POLL_S:-10}))
  done
  mkdir -p "$fleet/summary" || fail "$fleet/summary: cannot create"
  summary=$fleet/summary/$date.txt
  {
    echo "run $run, $date: per index the data set and fit's exit status (0 written; 5 refused:"
    echo "no calibration beat the nominal robot on the held-out runs, fit.txt beside it says why)"
    i=0
    while [ "$i" -lt "$robots" ]; do
      echo "  $i $(cat "$status_dir/$i" 2> /dev/null || echo '(no status)')"
      i=$((i + 1))
    done
    echo
  } > "$summary.tmp"
  fitcal fleet "$fleet/results" >> "$summary.tmp" 2>&1
  status=$?
  mv "$summary.tmp" "$summary"
  cat "$summary"
  exit "$status"
}

if [ "$index" -lt "$robots" ]; then
  calibrate
elif [ "$index" -eq "$robots" ]; then
  summarise
else
  fail "index $index, but $list lists $robots data sets: completions must be $((robots + 1))"
fi
