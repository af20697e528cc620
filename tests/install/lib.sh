# Shared by the install tests: a scratch folder $tmp (removed at exit; symbolic links resolved,
# as the program reports paths) and the check helpers of tests/cli/run.sh.
tmp=$(realpath "$(mktemp -d)")
trap 'rm -rf "$tmp"' EXIT
pass=0
fail=0

check() { # check NAME EXPECTED_EXIT COMMAND... ; output saved in $tmp/stdout and $tmp/stderr
  local name=$1 want=$2
  shift 2
  "$@" >"$tmp/stdout" 2>"$tmp/stderr"
  local got=$?
  if [ "$got" -eq "$want" ]; then pass=$((pass + 1)); else
    fail=$((fail + 1))
    echo "FAIL $name: exit $got, expected $want"
    sed 's/^/  /' "$tmp/stderr" | tail -15
  fi
}
contains() { # contains NAME FILE TEXT
  if grep -qF -- "$3" "$2"; then pass=$((pass + 1)); else
    fail=$((fail + 1))
    echo "FAIL $1: '$3' not in $2"
    sed 's/^/  /' "$2" | head -10
  fi
}
lacks() { # lacks NAME FILE TEXT
  if ! grep -qF -- "$3" "$2"; then pass=$((pass + 1)); else
    fail=$((fail + 1))
    echo "FAIL $1: '$3' in $2"
    grep -F -- "$3" "$2" | head -5 | sed 's/^/  /'
  fi
}
same() { # same NAME FILE1 FILE2
  if cmp -s "$2" "$3"; then pass=$((pass + 1)); else
    fail=$((fail + 1))
    echo "FAIL $1: $2 differs from $3"
    diff "$2" "$3" | head -10 | sed 's/^/  /'
  fi
}
exists() { # exists NAME PATH
  if [ -e "$2" ]; then pass=$((pass + 1)); else
    fail=$((fail + 1))
    echo "FAIL $1: $2 missing"
  fi
}
finish() {
  echo "$pass passed, $fail failed"
  [ "$fail" -eq 0 ]
}

# Whether this machine lets us lay an empty folder over the source tree in a private mount
# namespace (root, or unprivileged user namespaces): then the source tree is really out of reach.
can_hide() {
  unshare -rm true 2>/dev/null
}
# hidden DIR COMMAND...: runs COMMAND with DIR hidden under an empty tmpfs
hidden() {
  local dir=$1
  shift
  unshare -rm sh -c 'mount -t tmpfs none "$1" && shift && exec "$@"' sh "$dir" "$@"
}
