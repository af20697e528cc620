# Sourced by the command-line test scripts: a scratch folder $tmp (removed at exit; symbolic
# links resolved, as the program reports paths), the counts $pass and $fail, and the checks,
# which print a FAIL line (and what was seen) when they do not hold.
tmp=$(realpath "$(mktemp -d)")
trap 'rm -rf "$tmp"' EXIT
pass=0
fail=0
ok() { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAIL $*"; }
check() { # check NAME EXPECTED_EXIT COMMAND... ; output saved in $tmp/stdout and $tmp/stderr
  local name=$1 want=$2
  shift 2
  "$@" >"$tmp/stdout" 2>"$tmp/stderr"
  local got=$?
  if [ "$got" -eq "$want" ]; then ok; else
    bad "$name: exit $got, expected $want"
    sed 's/^/  /' "$tmp/stderr" | head -10
  fi
}
contains() { # contains NAME FILE TEXT
  if grep -qF -- "$3" "$2"; then ok; else
    bad "$1: '$3' not in $2"
    sed 's/^/  /' "$2" | head -10
  fi
}
holds() { # holds NAME COMMAND... : the command succeeds
  local name=$1
  shift
  if "$@"; then ok; else bad "$name"; fi
}
lacks() { # lacks NAME FILE TEXT
  if ! grep -qF -- "$3" "$2"; then ok; else
    bad "$1: '$3' in $2"
    grep -F -- "$3" "$2" | head -5 | sed 's/^/  /'
  fi
}
