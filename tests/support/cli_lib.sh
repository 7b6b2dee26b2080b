# Shared by the command-line tests (sourced after `tmp` is set).
# fails WHAT-THE-MESSAGE-NAMES COMMAND...: COMMAND exits with status 2 and its stderr names WHAT.
fails() {
  local want=$1 status=0
  shift
  "$@" >"$tmp/out.txt" 2>"$tmp/err.txt" || status=$?
  if [ "$status" != 2 ]; then
    echo "expected status 2 from: $* (got $status)" >&2
    cat "$tmp/err.txt" >&2
    exit 1
  fi
  grep -q -- "$want" "$tmp/err.txt" || { cat "$tmp/err.txt" >&2; exit 1; }
}
