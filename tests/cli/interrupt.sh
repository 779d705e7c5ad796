# Sourced by the Ctrl-C tests: interrupt PID OUTPUT... sends SIGINT to PID, waits for it, prints
# the OUTPUT files, and fails unless it exited with status 130 within half a second. Sets $ms.
interrupt() {
  pid=$1
  shift
  kill -INT "$pid"
  sent=$(date +%s%N)
  wait "$pid"
  status=$?
  ms=$((($(date +%s%N) - sent) / 1000000))
  cat "$@"
  [ $status -eq 130 ] || { echo "FAIL: exit status $status, not 130"; exit 1; }
  [ $ms -le 500 ] || { echo "FAIL: took $ms ms to stop"; exit 1; }
}
