#!/usr/bin/env bash
# Command-line behaviour that script tests cannot reach: help on every command, usage errors,
# unreadable input, and exit codes.
set -u
plant=$(realpath "${1:?usage: run.sh PLANT}")
. "$(dirname "$0")/checks.sh"
differ() { # differ NAME FILE1 FILE2
  if ! cmp -s "$2" "$3"; then pass=$((pass + 1)); else
    fail=$((fail + 1))
    echo "FAIL $1: $2 and $3 are the same"
  fi
}

printf 'axiom: F;\nderive 2;\nrules { F -> F+F; }\n' >"$tmp/ok.plant"

check "top-level help" 0 "$plant" --help
contains "top-level help lists derive" "$tmp/stdout" "derive"
for cmd in run derive check test; do
  check "$cmd --help" 0 "$plant" "$cmd" --help
  contains "$cmd --help shows usage" "$tmp/stdout" "Usage"
done
check "no command" 64 "$plant"
# plant help: the commands and topics, each topic printed from its table
check "help" 0 "$plant" help
contains "help lists commands" "$tmp/stdout" "derive"
contains "help lists topics" "$tmp/stdout" "builtins"
check "help --help" 0 "$plant" help --help
contains "help --help shows usage" "$tmp/stdout" "Usage"
check "help builtins" 0 "$plant" help builtins
contains "help builtins has docs" "$tmp/stdout" "uniform(number, number) -> number"
contains "help builtins marks random draws" "$tmp/stdout" "draws random numbers"
check "help builtins --names" 0 "$plant" help builtins --names
contains "builtin names" "$tmp/stdout" "smoothstep"
check "help env" 0 "$plant" help env
contains "help env lists kinds" "$tmp/stdout" "climber"
check "help env KIND" 0 "$plant" help env climber
contains "help env KIND lists methods" "$tmp/stdout" "pull(number, vec3) -> number"
check "help env unknown kind" 64 "$plant" help env tree
check "help turtle" 0 "$plant" help turtle
contains "help turtle shows a symbol's parameters and doc" "$tmp/stdout" "@Tp(x, y, z)"
contains "help turtle lists query modules" "$tmp/stdout" "?E(env, slots...)"
check "help hooks" 0 "$plant" help hooks
contains "help hooks lists before_step" "$tmp/stdout" "before_step"
check "help operators" 0 "$plant" help operators
contains "help operators lists &&" "$tmp/stdout" "&&"
check "help formats" 0 "$plant" help formats
contains "help formats" "$tmp/stdout" ".skel.json"
check "help repl" 0 "$plant" help repl
contains "help repl" "$tmp/stdout" ":step [N]"
check "help of a command" 0 "$plant" help run
contains "help of a command shows usage" "$tmp/stdout" "Usage: plant run"
check "help unknown topic" 64 "$plant" help frobnicate
check "unknown command" 64 "$plant" grow
check "unknown option" 64 "$plant" derive "$tmp/ok.plant" --frobnicate
check "bad -n" 64 "$plant" derive "$tmp/ok.plant" -n minus
check "bad -D" 64 "$plant" derive "$tmp/ok.plant" -D nothing
check "missing file" 66 "$plant" derive "$tmp/none.plant"
contains "missing file message" "$tmp/stderr" "cannot read '$tmp/none.plant': no such file"
check "directory as file" 66 "$plant" check "$tmp"
check "derive ok" 0 "$plant" derive "$tmp/ok.plant"
contains "derive output" "$tmp/stdout" "F+F+F+F"
check "derive -n" 0 "$plant" derive "$tmp/ok.plant" -n 1
contains "derive -n output" "$tmp/stdout" "F+F"
check "derive --stats" 0 "$plant" derive "$tmp/ok.plant" --stats
contains "stats total line" "$tmp/stdout" "total steps=2 modules=7"
check "check ok" 0 "$plant" check "$tmp/ok.plant"
# random bytes after a fixed first byte that nothing can start with: random ones could open a
# comment or a line break, and the error would be on a later line (a flaky test)
printf '\x80' >"$tmp/garbage.plant"
head -c 4096 /dev/urandom >>"$tmp/garbage.plant"
printf '\x00\x01binary' >>"$tmp/garbage.plant"
check "binary garbage" 65 "$plant" derive "$tmp/garbage.plant"
contains "binary garbage is positioned" "$tmp/stderr" "garbage.plant:1:1:"
: >"$tmp/empty.plant"
check "empty file" 65 "$plant" derive "$tmp/empty.plant"
contains "empty file message" "$tmp/stderr" "the grammar has no axiom"
printf 'axiom: F;\nderive 40;\nrules { F -> FF; }\n' >"$tmp/boom.plant"
check "explosion" 70 "$plant" derive "$tmp/boom.plant" --max-modules 1000
contains "explosion names the step" "$tmp/stderr" "step 10: the string grew past the limit of 1000 modules"
check "threads agree" 0 "$plant" derive "$tmp/ok.plant" --threads 2
check "test of missing path" 66 "$plant" test "$tmp/none"

# plant run
printf 'surface leaf = polygon(vec3(0,0,0), vec3(1,1,0), vec3(0,2,0));\naxiom: F [ + F ~leaf(1) ] F;\n' >"$tmp/plant.plant"
(cd "$tmp" && check "run with default outputs" 0 "$plant" run plant.plant)
for f in out/plant.glb out/plant.png; do
  if [ -s "$tmp/$f" ]; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAIL default output $f missing"; fi
done
check "run every format" 0 "$plant" run "$tmp/plant.plant" -o "$tmp/a.glb" -o "$tmp/a.gltf" -o "$tmp/a.obj" \
  -o "$tmp/a.ply" -o "$tmp/a.off" -o "$tmp/a.png" -o "$tmp/a.svg" -o "$tmp/a.txt" -o "$tmp/a.skel.json" -o "$tmp/a.mesh.txt"
for f in a.glb a.gltf a.obj a.ply a.off a.png a.svg a.txt a.skel.json a.mesh.txt; do
  if [ -s "$tmp/$f" ]; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAIL output $f missing"; fi
done
contains "PNG signature" "$tmp/a.png" "PNG"
contains "string output" "$tmp/a.txt" "F[+F~leaf(1)]F"
contains "mesh summary" "$tmp/a.mesh.txt" "instances 1"

# glTF placements: GPU instancing by default, plain nodes, or everything baked
printf 'surface leaf = polygon(vec3(0,0,0), vec3(1,1,0), vec3(0,2,0));\naxiom: F [ + F ~leaf(1) ] F [ - F ~leaf(1) ] F ~leaf(1);\n' >"$tmp/leaves.plant"
check "run instanced" 0 "$plant" run "$tmp/leaves.plant" -o "$tmp/i.gltf"
contains "instanced by default" "$tmp/i.gltf" '"EXT_mesh_gpu_instancing"'
contains "one instanced node for the leaves" "$tmp/i.gltf" '"name": "leaf"'
check "run --no-gpu-instancing" 0 "$plant" run "$tmp/leaves.plant" --no-gpu-instancing -o "$tmp/p.gltf"
lacks "--no-gpu-instancing writes plain nodes" "$tmp/p.gltf" "EXT_mesh_gpu_instancing"
contains "--no-gpu-instancing keeps matrices" "$tmp/p.gltf" '"matrix"'
check "run --flatten" 0 "$plant" run "$tmp/leaves.plant" --flatten -o "$tmp/f.gltf"
lacks "--flatten writes no instancing" "$tmp/f.gltf" "EXT_mesh_gpu_instancing"
lacks "--flatten writes no matrices" "$tmp/f.gltf" '"matrix"'
lacks "--flatten shares no leaf mesh" "$tmp/f.gltf" '"name": "leaf"'
check "--flatten with --no-gpu-instancing" 64 "$plant" run "$tmp/leaves.plant" --flatten --no-gpu-instancing -o "$tmp/x.glb"
check "run --help lists --flatten" 0 "$plant" run --help
contains "--help explains --no-gpu-instancing" "$tmp/stdout" "--no-gpu-instancing"
contains "--help explains --camera" "$tmp/stdout" "--camera"
contains "--help explains --look-at" "$tmp/stdout" "--look-at"

# the PNG preview from a camera
check "run --camera" 0 "$plant" run "$tmp/leaves.plant" --camera 0,2,10 --size 64x64 -o "$tmp/cam.png"
check "run default view" 0 "$plant" run "$tmp/leaves.plant" --size 64x64 -o "$tmp/default.png"
differ "--camera changes the PNG" "$tmp/cam.png" "$tmp/default.png"
check "run --camera --look-at" 0 "$plant" run "$tmp/leaves.plant" --camera=-4,1,-6 --look-at 0,3,0 --size 64x64 -o "$tmp/at.png"
differ "--look-at changes the PNG" "$tmp/cam.png" "$tmp/at.png"
check "--look-at alone" 64 "$plant" run "$tmp/leaves.plant" --look-at 0,1,0 -o "$tmp/x.png"
contains "--look-at alone message" "$tmp/stderr" "--look-at needs --camera"
for bad in "1,2" "1,2,3,4" "a,b,c" "1,2,nan" "1,2,inf" "" "1;2;3"; do
  check "bad --camera '$bad'" 64 "$plant" run "$tmp/leaves.plant" --camera "$bad" -o "$tmp/x.png"
done
contains "bad --camera message" "$tmp/stderr" "--camera expects three finite numbers x,y,z"
check "bad --look-at" 64 "$plant" run "$tmp/leaves.plant" --camera 1,2,3 --look-at 1,2 -o "$tmp/x.png"
contains "bad --look-at message" "$tmp/stderr" "--look-at expects three finite numbers"
check "--camera at --look-at" 64 "$plant" run "$tmp/leaves.plant" --camera 1,2,3 --look-at 1,2,3 -o "$tmp/x.png"
contains "--camera at --look-at message" "$tmp/stderr" "are the same point"
if [ -e "$tmp/x.png" ] || [ -e "$tmp/x.glb" ]; then fail=$((fail + 1)); echo "FAIL output after a usage error"; else pass=$((pass + 1)); fi

# an environment's obstacles go into meshes and images as one more prototype, unless left out
printf 'env wall = obstacles(box_min: vec3(-1, 0, -1), box_max: vec3(1, 1, -0.5));\naxiom: F;\n' >"$tmp/wall.plant"
check "run with obstacles" 0 "$plant" run "$tmp/wall.plant" -o "$tmp/w.mesh.txt"
contains "obstacles are shown" "$tmp/w.mesh.txt" "prototypes 1"
contains "obstacles are shown as a box" "$tmp/w.mesh.txt" "triangles 28"
check "run --no-obstacles" 0 "$plant" run "$tmp/wall.plant" --no-obstacles -o "$tmp/n.mesh.txt"
contains "--no-obstacles leaves them out" "$tmp/n.mesh.txt" "prototypes 0"
check "unknown output format" 64 "$plant" run "$tmp/plant.plant" -o "$tmp/a.xyz"
contains "format message" "$tmp/stderr" "cannot tell the format of"
check "bad --size" 64 "$plant" run "$tmp/plant.plant" --size 10 -o "$tmp/b.png"
mkdir -p "$tmp/ro" && chmod 555 "$tmp/ro"
if [ "$(id -u)" -ne 0 ]; then
  check "unwritable output" 73 "$plant" run "$tmp/plant.plant" -o "$tmp/ro/x.glb"
fi
printf 'axiom: F ] F;\n' >"$tmp/pop.plant"
check "empty turtle stack" 70 "$plant" run "$tmp/pop.plant" -o "$tmp/pop.glb" -o "$tmp/pop.png"
contains "empty stack message" "$tmp/stderr" "closes no '['"
if [ -e "$tmp/pop.glb" ] || [ -e "$tmp/pop.png" ]; then fail=$((fail + 1)); echo "FAIL partial output after an error"; else pass=$((pass + 1)); fi
# all or nothing: one output that cannot be written means none is left behind
check "one unwritable output of two" 73 "$plant" run "$tmp/plant.plant" -o "$tmp/both.glb" -o /proc/nope/x.png
if [ -e "$tmp/both.glb" ]; then fail=$((fail + 1)); echo "FAIL both.glb left behind"; else pass=$((pass + 1)); fi
if ls -a "$tmp" | grep -q plant-tmp; then fail=$((fail + 1)); echo "FAIL temporary files left behind"; else pass=$((pass + 1)); fi
# an output whose folder cannot be: refused before any work (the grammar's start hook never prints)
printf 'derive 2;\naxiom: F;\nrules { F -> FF; }\non start { print("started"); }\n' >"$tmp/hook.plant"
: >"$tmp/afile"
check "an output under a file" 73 "$plant" run "$tmp/hook.plant" -o "$tmp/x.glb" -o "$tmp/afile/x.png"
contains "an output under a file: why" "$tmp/stderr" "cannot write '$tmp/afile/x.png': cannot create a file in '$tmp/afile': Not a directory"
lacks "an output under a file: before any work" "$tmp/stderr" "started"
# a placeholder is a batch's: a single run refuses it rather than writing '{seed}' into a name
check "a placeholder in a single run" 64 "$plant" run "$tmp/hook.plant" --seed 5 -o "$tmp/x-{seed}.glb"
contains "a placeholder in a single run: what to do" "$tmp/stderr" "holds the placeholder {seed}, which only a batch fills in: give --seeds S..S"
# a .glb goes to its file piece by piece: a write refused part way (here the file-size limit, 64 kB
# of a 640 kB file) is an error that leaves neither the file nor a temporary one
mkdir -p "$tmp/full"
check "a .glb over the file-size limit" 73 bash -c 'trap "" XFSZ; ulimit -f 64; exec "$0" run "$1" -o "$2"' \
  "$plant" "$(dirname "$0")/../../grammars/abop/fig2_7a.plant" "$tmp/full/big.glb"
contains "file too large" "$tmp/stderr" "cannot write '$tmp/full/big.glb': File too large"
if [ -n "$(ls -A "$tmp/full")" ]; then fail=$((fail + 1)); echo "FAIL a partial .glb left behind"; else pass=$((pass + 1)); fi
# all or nothing across the run: a folder where the second output goes keeps the first file as it was
mkdir -p "$tmp/keep" "$tmp/keep/b.skel.json" && echo old >"$tmp/keep/a.txt"
check "second output is a folder" 73 "$plant" run "$tmp/plant.plant" -o "$tmp/keep/a.txt" -o "$tmp/keep/b.skel.json"
contains "the target is named" "$tmp/stderr" "cannot write '$tmp/keep/b.skel.json'"
contains "the first output keeps its old contents" "$tmp/keep/a.txt" "old"
# a run that fails leaves no folder it made for its outputs (here the first output's name is a
# folder the second output's path made)
check "an output inside another output" 73 "$plant" run "$tmp/plant.plant" -o "$tmp/made/a/x.glb" \
  -o "$tmp/made/a/x.glb/y.png"
if [ -e "$tmp/made" ]; then bad "a failed run left the folders it made: $(find "$tmp/made" | head -3)"; else ok; fi
mkdir -p "$tmp/mine/kept"
check "a failed run in a folder of the user's" 73 "$plant" run "$tmp/plant.plant" -o "$tmp/mine/new/x.glb" \
  -o "$tmp/plant.plant/x.png"
if [ -e "$tmp/mine/new" ] || [ ! -d "$tmp/mine/kept" ]; then bad "folders: made one left, or the user's removed"; else ok; fi
# an output (or an OBJ's .mtl) that is the grammar itself is refused before anything is written
cp "$tmp/plant.plant" "$tmp/self.txt"
check "the grammar as its own output" 64 "$plant" run "$tmp/self.txt" -o "$tmp/self.txt"
contains "says why" "$tmp/stderr" "is the grammar being run"
cp "$tmp/plant.plant" "$tmp/self.mtl"
check "the grammar as an OBJ's .mtl" 64 "$plant" run "$tmp/self.mtl" -o "$tmp/self.obj"
if cmp -s "$tmp/plant.plant" "$tmp/self.mtl" && [ ! -e "$tmp/self.obj" ]; then ok; else bad "the grammar was replaced"; fi
# angle, step and width settings are finite (width 0 or more): `plant check` sees it
printf 'axiom: F + F;\nwidth sqrt(-1);\n' >"$tmp/nanwidth.plant"
check "a width that is not a number" 65 "$plant" check "$tmp/nanwidth.plant"
contains "the width's error, at the setting" "$tmp/stderr" "nanwidth.plant:2:7: error: the width must be a finite number"
printf 'param a = 0;\nparam big = 1e308;\naxiom: F + F;\nangle big * (10 + a);\n' >"$tmp/infangle.plant"
check "an angle that overflows" 65 "$plant" check "$tmp/infangle.plant"
contains "the angle's error, at the setting" "$tmp/stderr" "infangle.plant:4:7: error: the angle must be a finite number, found inf"
# SIGINT while a slow output is being made removes the temporary files already written and the
# folders made for them, and ends the process by the signal (job control, so the background run
# does not ignore SIGINT); SIGHUP (the terminal closed) the same
printf 'axiom: A;\nderive 15;\nrules { A -> F[+A][-A]; }\n' >"$tmp/slow.plant"
for sig in INT HUP; do
  rm -rf "$tmp/sig"
  mkdir -p "$tmp/sig/kept" # an empty folder that was there before stays, though named through '..'
  set -m
  "$plant" run "$tmp/slow.plant" -o "$tmp/sig/s.txt" -o "$tmp/sig/new/../kept/s.off" -o "$tmp/sig/new/deep/s.png" \
    -o "$tmp/sig/s.obj" --sides 64 --size 12000x5000 >/dev/null 2>&1 &
  slow=$!
  set +m
  for _ in $(seq 200); do
    ls -a "$tmp/sig/new/deep" 2>/dev/null | grep -q plant-tmp && break
    sleep 0.05
  done
  kill -s $sig "$slow" 2>/dev/null
  wait "$slow"
  got=$?
  want=$((128 + $(kill -l $sig)))
  if [ "$got" -eq $want ]; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAIL SIG$sig during run: exit $got, expected $want"; fi
  if ls -a "$tmp/sig" | grep -qv '^\.\.\?$\|^kept$' || [ ! -d "$tmp/sig/kept" ] || [ -n "$(ls -A "$tmp/sig/kept")" ]; then
    fail=$((fail + 1)); echo "FAIL SIG$sig during run left files:"; ls -a "$tmp/sig"
  else pass=$((pass + 1)); fi
done
check "upper-case extension" 0 "$plant" run "$tmp/plant.plant" -o "$tmp/UP.GLB"
printf 'axiom: F @R(1e308, 1e308, 0) F;\n' >"$tmp/huge.plant"
check "huge heading" 0 "$plant" run "$tmp/huge.plant" -o "$tmp/huge.skel.json"
if grep -q nan "$tmp/huge.skel.json"; then fail=$((fail + 1)); echo "FAIL NaN in the skeleton"; else pass=$((pass + 1)); fi
printf 'axiom: F(1e39);\n' >"$tmp/far.plant"
check "beyond single precision" 70 "$plant" run "$tmp/far.plant" -o "$tmp/far.glb"
# the REPL: exit codes of scripts
printf ':step 1\n' >"$tmp/ok.repl"
printf ':step x\n:step 1\n' >"$tmp/bad.repl"
check "repl script" 0 "$plant" repl "$tmp/plant.plant" <"$tmp/ok.repl"
check "repl script with a failing line" 1 "$plant" repl "$tmp/plant.plant" <"$tmp/bad.repl"
check "repl with a missing file" 66 "$plant" repl "$tmp/none.plant"
printf 'axiom: F ~nothing(1);\n' >"$tmp/nosurf.plant"
check "undeclared surface" 65 "$plant" run "$tmp/nosurf.plant" -o "$tmp/n.glb"
contains "undeclared surface: at the module" "$tmp/stderr" "nosurf.plant:1:10: error: '~nothing' places a surface that is not declared"

# a first word that is no command is named, with the commands
check "an unknown command" 64 "$plant" nosuchcmd
contains "the unknown command named" "$tmp/stderr" "plant: unknown command 'nosuchcmd' (the commands: run, derive,"
check "a misspelt command" 64 "$plant" drive "$tmp/plant.plant"
contains "a misspelt command: the nearest" "$tmp/stderr" "plant: unknown command 'drive'; did you mean 'derive'?"
check "a misspelt option" 64 "$plant" derive "$tmp/plant.plant" --step 3
contains "a misspelt option: the nearest" "$tmp/stderr" "plant: derive has no option --step; did you mean --steps?"
check "a misspelt option with its value" 64 "$plant" run "$tmp/plant.plant" --sed=3
contains "a misspelt option with its value: the nearest" "$tmp/stderr" "plant: run has no option --sed; did you mean --seed?"
# help and the version, written to a full disk, fail as any output does
for words in "derive --help" "--version" "help turtle" "--help-all"; do
  # shellcheck disable=SC2086 # the words are split on purpose
  check "plant $words > /dev/full" 73 bash -c '"$0" "$@" >/dev/full' "$plant" $words
done
check "plant graph > /dev/full" 73 bash -c '"$0" graph "$1" >/dev/full' "$plant" "$(dirname "$0")/../../grammars/bonsai/bunjingi.plant"
contains "plant graph > /dev/full: why" "$tmp/stderr" "plant: cannot write the graph to standard output"
# the grammar named on the command line may be a pipe, but not a device (/dev/zero never ends)
check "a device as the grammar" 66 "$plant" check /dev/zero
contains "a device as the grammar: why" "$tmp/stderr" "plant: cannot read '/dev/zero': it is not a regular file"

# a number option out of its range says what to give, in the option's own terms
check "--width-scale 0" 64 "$plant" run "$tmp/ok.plant" --width-scale 0 -o "$tmp/w.glb"
contains "--width-scale 0: what to give" "$tmp/stderr" "plant: --width-scale: must be a number above 0 and at most 1000000, found '0'"
check "--sides 3.5" 64 "$plant" run "$tmp/ok.plant" --sides 3.5 -o "$tmp/w.glb"
contains "--sides 3.5: what to give" "$tmp/stderr" "plant: --sides: must be a whole number from 3 to 64, found '3.5'"
check "--timeout 0" 64 "$plant" test "$tmp/ok.plant" --timeout 0
contains "--timeout 0: what to give" "$tmp/stderr" "plant: --timeout: must be a number from 0.1 to 86400, found '0'"
check "--port 70000" 64 "$plant" view "$tmp/ok.plant" --port 70000
contains "--port 70000: what to give" "$tmp/stderr" "plant: --port: must be a whole number from 0 to 65535, found '70000'"
check "in range" 0 "$plant" run "$tmp/ok.plant" --width-scale 1000000 --sides 64 --min-line-width 0 -o "$tmp/w.glb"
# a whole number is read in decimal, whatever its spelling: 010 is ten sides (CLI11 alone read eight)
check "--sides 010" 0 "$plant" run "$tmp/ok.plant" --sides 010 -o "$tmp/s010.mesh.txt"
check "--sides 10" 0 "$plant" run "$tmp/ok.plant" --sides 10 -o "$tmp/s10.mesh.txt"
check "--sides 8" 0 "$plant" run "$tmp/ok.plant" --sides 8 -o "$tmp/s8.mesh.txt"
holds "--sides 010 is ten" cmp -s "$tmp/s010.mesh.txt" "$tmp/s10.mesh.txt"
differ "--sides 010 is not eight" "$tmp/s010.mesh.txt" "$tmp/s8.mesh.txt"
check "--sides 1e1" 0 "$plant" run "$tmp/ok.plant" --sides 1e1 -o "$tmp/s1e1.mesh.txt"
holds "--sides 1e1 is ten" cmp -s "$tmp/s1e1.mesh.txt" "$tmp/s10.mesh.txt"

# the same output named twice is refused before any work; --size with no image, and a plant that
# draws nothing, are warned about
check "an output named twice" 64 "$plant" run "$tmp/ok.plant" -o "$tmp/twice.png" -o "$tmp/./twice.png"
contains "an output named twice: why" "$tmp/stderr" "is given twice as an output: name each file once"
holds "an output named twice: nothing written" test ! -e "$tmp/twice.png"
check "--size with no image" 0 "$plant" run "$tmp/ok.plant" --size 64x64 -o "$tmp/size.glb"
contains "--size with no image: warned" "$tmp/stderr" "plant: warning: --size sets the size of .png and .svg outputs, and none is written"
check "--size with an image" 0 "$plant" run "$tmp/ok.plant" --size 64x64 -o "$tmp/size.png"
lacks "--size with an image: no warning" "$tmp/stderr" "warning"
printf 'axiom: A;\nderive 2;\nrules { A -> A B; }\n' >"$tmp/draws_nothing.plant"
check "a plant that draws nothing" 0 "$plant" run "$tmp/draws_nothing.plant" -o "$tmp/nothing.glb"
contains "a plant that draws nothing: warned" "$tmp/stderr" "plant: warning: the plant draws nothing: no tube, organ or instance came of its string (3 modules after 2 steps)"
check "a string of nothing drawn, as text" 0 "$plant" run "$tmp/draws_nothing.plant" -o "$tmp/nothing.txt"
lacks "a string of nothing drawn, as text: no warning" "$tmp/stderr" "warning"

# the turtle's runtime errors name the string they count modules in: an instance's own, or the
# string the interpret rules make
printf 'instance B(w) { axiom: F F F !(w) F; }\nderive 1;\naxiom: A(-1);\nrules { A(w) -> F [ B(w) ]; }\n' >"$tmp/inst_width.plant"
check "a width below 0 in an instance" 70 "$plant" run "$tmp/inst_width.plant" -o "$tmp/inst_width.glb"
contains "a width below 0 in an instance: which string" "$tmp/stderr" "instance B(-1): module 4 of the string, !(-1), gives a width below 0"
printf 'derive 1;\naxiom: A(-1);\nrules { A(x) -> A(x); }\ninterpret { A(x) -> F F !(x) F; }\n' >"$tmp/interp_width.plant"
check "a width below 0 from interpret rules" 70 "$plant" run "$tmp/interp_width.plant" -o "$tmp/interp_width.glb"
contains "a width below 0 from interpret rules: which string" "$tmp/stderr" "module 3 of the interpreted string (after the interpret rules), !(-1)"

# plant test hands its child a file named like an option as a file
mkdir -p "$tmp/dashes"
printf '# expect: FF\nderive 1;\naxiom: F;\nrules { F -> FF; }\n' >"$tmp/dashes/-x.plant"
check "plant test of -x.plant" 0 "$plant" test "$tmp/dashes"
check "plant test -" 66 "$plant" test -
contains "plant test -: why" "$tmp/stderr" "does not read standard input"

# FILE '-': the grammar from standard input, named <stdin> in messages, read once for a batch
from() { local input=$1; shift; "$@" <"$input"; } # from FILE COMMAND...: COMMAND reading FILE
printf 'axiom: F;\nrules { F -> FF; }\n' >"$tmp/piped.plant"
check "derive -" 0 from "$tmp/piped.plant" "$plant" derive - -n 2
contains "derive -: the string" "$tmp/stdout" "FFFF"
cat "$tmp/piped.plant" | "$plant" derive - -n 3 >"$tmp/stdout" 2>&1
contains "derive - from a pipe" "$tmp/stdout" "FFFFFFFF"
printf 'axiom: F;\nrules { F -> F(1 +; }\n' >"$tmp/piped_bad.plant"
check "check - with an error" 65 from "$tmp/piped_bad.plant" "$plant" check -
contains "check -: the error names <stdin>" "$tmp/stderr" "<stdin>:2:19: error"
check "run - without -o" 64 from "$tmp/piped.plant" "$plant" run - -n 1
contains "run - without -o: why" "$tmp/stderr" "give them with -o"
check "run - -o" 0 from "$tmp/piped.plant" "$plant" run - -n 1 -o "$tmp/piped.txt"
contains "run - -o: the string" "$tmp/piped.txt" "FF"
printf 'axiom: F;\nderive 2;\nrules { F -> F[+F] : 0.5; F -> F[-F] : 0.5; }\n' >"$tmp/piped_batch.plant"
check "a batch of -" 0 from "$tmp/piped_batch.plant" "$plant" run - --seeds 1..4 --jobs 2 -o "$tmp/pb-{seed}.txt"
holds "a batch of -: every variant" test -s "$tmp/pb-1.txt" -a -s "$tmp/pb-4.txt"
check "derive - of empty input" 66 from /dev/null "$plant" derive -
contains "derive - of empty input: why" "$tmp/stderr" "standard input was empty"
check "view -" 64 from "$tmp/piped.plant" "$plant" view -
contains "view -: why" "$tmp/stderr" "needs a file"
if command -v script >/dev/null; then # a terminal as standard input would wait for typing
  script -qec "$plant check -" /dev/null </dev/null >"$tmp/stdout" 2>&1
  got=$?
  if [ "$got" -eq 64 ]; then ok; else bad "check - on a terminal: exit $got, expected 64"; fi
  contains "check - on a terminal: why" "$tmp/stdout" "which is a terminal here"
fi
check "a pipe as the grammar" 0 bash -c '"$0" derive <(printf "axiom: F;\n")' "$plant"
contains "a pipe as the grammar: derived" "$tmp/stdout" "F"
# a UTF-8 byte-order mark before the first line is skipped
printf '\xef\xbb\xbfaxiom: F;\n' >"$tmp/bom.plant"
check "a byte-order mark" 0 "$plant" derive "$tmp/bom.plant"
contains "a byte-order mark: the string" "$tmp/stdout" "F"

# a failed run removes the folders it made, and only those: one named through '..' that was
# there before stays, empty as it is
mkdir -p "$tmp/empty_before"
: >"$tmp/afile"
check "a run failing after making a folder" 73 "$plant" run "$tmp/ok.plant" -o "$tmp/made/../empty_before/s.txt" -o "$tmp/made2/s.txt" -o "$tmp/afile/x.txt"
contains "a run failing after making a folder: why" "$tmp/stderr" "cannot create a file in"
holds "the folder that was there stays" test -d "$tmp/empty_before"
holds "the folders the run made go" test ! -e "$tmp/made" -a ! -e "$tmp/made2"
# counts on the command line: one message naming the option, its range and what was written
check "--steps in hex" 64 "$plant" derive "$tmp/ok.plant" -n 0x10
contains "--steps in hex: the range" "$tmp/stderr" "plant: --steps must be a whole number from 0 to 1000000, found '0x10'"
check "--threads past 256" 64 "$plant" derive "$tmp/ok.plant" --threads 300
contains "--threads past 256: the range" "$tmp/stderr" "--threads must be a whole number from 0 to 256, found '300'"
check "--max-modules 0" 64 "$plant" derive "$tmp/ok.plant" --max-modules 0
contains "--max-modules 0: the range" "$tmp/stderr" "--max-modules must be a whole number from 1 to"
check "--max-steps 0" 64 "$plant" derive "$tmp/ok.plant" --max-steps 0
contains "--max-steps 0: the range" "$tmp/stderr" "--max-steps must be a whole number from 1 to"
check "--max-work -1" 64 "$plant" derive "$tmp/ok.plant" --max-work -1
contains "--max-work -1: the range" "$tmp/stderr" "--max-work must be a whole number from 1 to"
check "repl --max-steps x" 64 "$plant" repl "$tmp/plant.plant" --max-steps x <"$tmp/ok.repl"
contains "repl --max-steps x: the range" "$tmp/stderr" "--max-steps must be a whole number from 1 to"
check "repl --max-modules 0" 64 "$plant" repl "$tmp/plant.plant" --max-modules 0 <"$tmp/ok.repl"
contains "repl --max-modules 0: the range" "$tmp/stderr" "--max-modules must be a whole number from 1 to"

# carriage returns alone end lines (classic Mac OS files): a comment stops at one, and a
# diagnostic names the line
printf '# a comment\rderive 2;\raxiom: F;\rrules {\r  F -> F F;\r}\r' >"$tmp/cr.plant"
check "CR line endings" 0 "$plant" derive "$tmp/cr.plant"
contains "CR line endings: the string" "$tmp/stdout" "FFFF"
printf '# a comment\rderive 2;\raxiom: F;\rrules {\r  F -> F F(;\r}\r' >"$tmp/cr_bad.plant"
check "CR line endings, an error" 65 "$plant" derive "$tmp/cr_bad.plant"
contains "CR line endings: the error's line" "$tmp/stderr" "cr_bad.plant:5:12: error"

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ] && [ "$pass" -gt 0 ] # running nothing is a failure too
