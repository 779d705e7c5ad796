# Sourced by the glove tests. start_fake FAKE_WEART DIR [ARGS...]: starts the fake WEART middleware
# logging to DIR/fake.log (killed when the script exits) and sets $fake_pid and $fake_port.
# stop_fake: stops it (it flushes its log as it exits). released: fails unless the log's last
# command to each thimble stopped it.
start_fake() {
  fake=$1 fake_dir=$2
  shift 2
  "$fake" --port 0 --seconds 120 --log "$fake_dir/fake.log" "$@" > "$fake_dir/fake.out" 2>&1 &
  fake_pid=$!
  trap 'kill $fake_pid 2>/dev/null || true' EXIT
  for _ in $(seq 50); do grep -q '^listening on' "$fake_dir/fake.out" 2>/dev/null && break; sleep 0.1; done
  fake_port=$(sed -n 's/^listening on 127\.0\.0\.1:\([0-9]*\).*/\1/p' "$fake_dir/fake.out")
  [ -n "$fake_port" ] || { echo "FAIL: the fake middleware did not start"; cat "$fake_dir/fake.out"; exit 1; }
}
stop_fake() {
  kill -TERM "$fake_pid" && wait "$fake_pid" || true
  trap - EXIT
}
released() {
  for point in THUMB INDEX MIDDLE; do
    last=$(grep -E "(force|stopForce) RIGHT $point" "$fake_dir/fake.log" | tail -1)
    case "$last" in *stopForce*) ;; *) echo "FAIL: $point left pressing: $last"; exit 1 ;; esac
  done
}
