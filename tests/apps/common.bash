# Shared by the end-to-end scripts in tests/apps (sourced, not a test itself):
# strict mode, the environment ctest provides, a fresh scratch folder, and
# helpers to fail with a message and to check an exit code.
set -euo pipefail
bin=${ARTICULA_BIN:?}
tmp=${ARTICULA_TMP:?}
rm -rf "$tmp" && mkdir -p "$tmp"

# The Python that scripts/install-deps.sh installs its packages into
# (Debian's). A version manager's shim earlier on PATH would also be slower:
# pyenv's takes about 0.4 s a call, and the scripts make 150 calls.
python3() { /usr/bin/python3 "$@"; }

fail() { echo "FAIL: $*" >&2; exit 1; }

# expect_rc CODE command...: runs the command (stdout in $tmp/out, stderr in
# $tmp/err) and fails unless it exits with CODE.
expect_rc() {
  local want=$1; shift
  set +e; "$@" >"$tmp/out" 2>"$tmp/err"; local rc=$?; set -e
  [ "$rc" -eq "$want" ] || { cat "$tmp/err" >&2; fail "'$*' exited $rc, expected $want"; }
}
