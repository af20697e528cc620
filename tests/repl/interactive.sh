#!/usr/bin/env bash
# The REPL on a real terminal, driven through tmux: line editing (Left, C-a, Backspace), history
# (Up within a session, and across sessions through ~/.plant_history) and Tab completion of
# commands and param names.
#
#   tests/repl/interactive.sh PLANT
#
# Runs in a private tmux server (its own socket) with HOME set to a temporary directory, so the
# history starts empty and the user's own tmux and history are never touched. Every wait polls
# the screen (capture-pane) with a timeout instead of sleeping a fixed time.
set -u
if ! command -v tmux >/dev/null 2>&1; then
  echo "SKIP: tmux not installed"
  exit 0
fi
plant=$(realpath "${1:?usage: interactive.sh PLANT}")
tmp=$(mktemp -d)
sock=$tmp/tmux.sock
t() { tmux -S "$sock" "$@"; }
trap 't kill-server >/dev/null 2>&1; rm -rf "$tmp"' EXIT
home=$tmp/home
work=$tmp/work
mkdir -p "$home" "$work"
cat >"$work/g.plant" <<'EOF'
param branch_length = 2;
const growth = 2;
module A(x);
axiom: A(1);
rules { A(x) -> F(branch_length) [ + A(x + 1) ] A(x * growth); }
EOF
timeout=10 # seconds for any one wait
pass=0
fail=0

screen() { t capture-pane -p -J -S - -t repl; }
last_line() { screen | sed 's/[[:space:]]*$//' | grep -v '^$' | tail -n 1; } # tmux keeps trailing blanks
count() { screen | sed 's/[[:space:]]*$//' | grep -c -F -x -- "$1"; }
# poll until COMMAND... succeeds or the timeout passes
poll() {
  local end=$((SECONDS + timeout))
  until "$@"; do
    [ "$SECONDS" -ge "$end" ] && return 1
    sleep 0.05
  done
}
has() { screen | grep -q -F -- "$1"; }
line_is() { [ "$(last_line)" = "$1" ]; }
count_is() { [ "$(count "$1")" -ge "$2" ]; }
ok() { pass=$((pass + 1)); echo "ok   $1"; }
ko() {
  fail=$((fail + 1))
  echo "FAIL $1"
  echo "  --- screen ---"
  screen | grep -v '^[[:space:]]*$' | tail -n 15 | sed 's/^/  /'
}
expect_text() { if poll has "$2"; then ok "$1"; else ko "$1: '$2' never appeared"; fi; }
expect_line() { if poll line_is "$2"; then ok "$1"; else ko "$1: the last line never read '$2'"; fi; }
expect_count() { if poll count_is "$2" "$3"; then ok "$1"; else ko "$1: '$2' not seen $3 times"; fi; }
keys() { t send-keys -t repl "$@"; }
type_text() { t send-keys -t repl -l -- "$1"; }

# a plain shell in the pane (no rc files, no history file of its own): the REPL can be started,
# quit and started again
t new-session -d -s repl -x 120 -y 40 -c "$work" \
  "env -i HOME='$home' PATH='$PATH' TERM=xterm NO_COLOR=1 HISTFILE= PS1='shell\$ ' bash --norc --noprofile"
poll has 'shell$' || { ko "the shell did not start"; echo "$pass passed, $fail failed"; exit 1; }

# --- first session ---
type_text "$plant repl g.plant"
keys Enter
expect_text "the REPL starts with a prompt" "plant> "
[ "$fail" -eq 0 ] || { echo "$pass passed, $fail failed"; exit 1; } # nothing else can work
expect_text "the grammar is loaded" "loaded g.plant: 1 module at step 0"

# line editing: ':stp 2', three times Left puts the cursor before 'p', type the missing 'e'
type_text ":stp 2"
keys Left Left Left
type_text "e"
keys Enter
expect_text "Left moves the cursor: the fixed ':step 2' ran" "step 2: 16 modules"

# C-a: 'show' without its colon would be an expression (an unknown name); add the ':' in front
type_text "show"
keys C-a
type_text ":"
keys Enter
expect_text "C-a goes to the start: the fixed ':show' ran" "F(2)[+F(2)[+A(3)]A(4)]F(2)[+A(3)]A(4)"
if has "unknown name 'show'"; then ko "'show' was run unfixed"; else ok "the unfixed line did not run"; fi

# Backspace: ':find Q' becomes ':find A'
type_text ":find Q"
keys BSpace
type_text "A"
keys Enter
expect_count "Backspace deletes: the fixed ':find A' ran" "4 matches" 1

# history within the session: Up brings back ':find A'; run again, it is in the history twice,
# so ':show' is three lines up
keys Up
expect_line "Up recalls the previous command" "plant> :find A"
keys Enter
expect_count "the recalled command runs again" "4 matches" 2
keys Up Up Up
expect_line "Up three times recalls the command before" "plant> :show"
keys Enter
expect_count "which runs again" "F(2)[+F(2)[+A(3)]A(4)]F(2)[+A(3)]A(4)" 2

# Tab completion: a command, then a param name
type_text ":ste"
keys Tab
expect_line "Tab completes ':ste' to ':step'" "plant> :step"
keys Enter
expect_text "the completed ':step' ran" "step 3: 36 modules"
type_text "bra"
keys Tab
expect_line "Tab completes a param name" "plant> branch_length"
type_text "* 10 + 0.5"
keys Enter
expect_text "the completed expression is evaluated" "20.5"

# Tab completion by context: params and consts after :set, commands after :help, file names
# after :load, :render and :export
type_text ":set gro"
keys Tab
expect_line "Tab after :set completes a const" "plant> :set growth"
keys C-u
type_text ":set br"
keys Tab
expect_line "Tab after :set completes a param" "plant> :set branch_length"
keys C-u
type_text ":help rel"
keys Tab
expect_line "Tab after :help completes a command's name" "plant> :help reload"
keys C-u
type_text ":load g.pl"
keys Tab
expect_line "Tab after :load completes a file name" "plant> :load g.plant"
keys C-u
type_text ":render g.pl"
keys Tab
expect_line "Tab after :render completes a file name" "plant> :render g.plant"
keys C-u
type_text ":help gro"
keys Tab
expect_line "Tab after :help offers no param" "plant> :help gro"
keys C-u

type_text ":quit"
keys Enter
expect_line ":quit returns to the shell" 'shell$'
if [ -f "$home/.plant_history" ] && grep -q 'branch_length' "$home/.plant_history"; then
  ok "the history is saved in \$HOME/.plant_history"
else
  ko "no \$HOME/.plant_history with the session's commands"
fi

# --- second session: the history of the first one is there ---
# clear the screen and the scrollback, and make sure the first session's lines are gone, so
# that what follows can only come from the new session
no_repl_on_screen() { ! has 'plant>'; }
type_text "clear"
keys Enter
poll no_repl_on_screen
t clear-history -t repl
poll no_repl_on_screen || ko "the screen could not be cleared"
type_text "$plant repl g.plant"
keys Enter
expect_text "the REPL starts again" "plant> "
keys Up
expect_line "Up recalls the last command of the previous session" "plant> :quit"
keys Up
expect_line "and the one before it" "plant> branch_length * 10 + 0.5"
keys Enter
expect_text "the recalled command runs in the new session" "20.5"
keys C-d
expect_line "Ctrl-D on an empty line ends the session" 'shell$'

# --- third session: Ctrl-C stops a runaway evaluation (a budget that would last for hours) ---
cat >"$work/h.plant" <<'EOF'
fn f(n) = n > 0 ? f(n - 1) + f(n - 1) : 1;
var k = 0;
on before_step { for i in 0..1e7 { for j in 0..1e7 { k += 1; } } }
axiom: F;
EOF
type_text "$plant repl --max-steps 100000000000000 h.plant"
keys Enter
expect_text "the REPL starts with a runaway grammar" "loaded h.plant"
type_text "f(100)"
keys Enter
sleep 0.3
keys C-c
expect_text "Ctrl-C stops a runaway expression" "interrupted"
type_text ":step"
keys Enter
sleep 0.3
keys C-c
expect_text "Ctrl-C stops a runaway hook" "interrupted; still at step 0"
# Ctrl-C stops :render while it meshes (an instance whose derivation runs for hours), and
# nothing is written
cat >"$work/s.plant" <<'EOF'
instance Slow() { var k = 0; derive 1; axiom: F; on before_step { for i in 0..1e7 { for j in 0..1e7 { k += 1; } } } }
axiom: F Slow;
EOF
type_text ":load s.plant"
keys Enter
expect_text "a grammar with a slow instance loads" "loaded s.plant"
type_text ":render s.png"
keys Enter
sleep 0.3
keys C-c
expect_text "Ctrl-C stops :render" "interrupted; nothing written, still at step 0"
if [ -e "$work/s.png" ]; then ko ":render wrote s.png after Ctrl-C"; else ok "no s.png after Ctrl-C"; fi
type_text ":quit"
keys Enter
expect_line "the session goes on after both and quits" 'shell$'

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
