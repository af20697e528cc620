#!/usr/bin/env python3
"""The commands of README.md's shell blocks run as written.

Every line of a ```sh block that starts with `build/plant` or `printf` runs, in order, with
bash in a scratch folder that holds `build/plant` (the plant under test) and links to the
repository's `grammars/` and `bench/`, so outputs land in the scratch folder. Each must exit 0 within
120 s, and every `out/...` file its comment names must then exist. Three kinds of line are
changed or left out, and said so in the output (and `make` lines are not `plant` commands: not run):
- `plant test ...` is not run: ctest runs the same golden files and scripts itself (and
  `--bless` would rewrite the repository's files);
- `plant view` and `plant repl` are not run: they serve or read a terminal until stopped (their
  own tests are tests/cli/view.sh, tests/view and tests/repl);
- `--seeds 1..1000` runs as `--seeds 1..12`: the same syntax and outputs, in a fraction of the time.

usage: readme_commands.py PLANT SOURCE_DIR
"""
import os
import re
import subprocess
import sys
import tempfile


def sh_lines(readme):
    lines, inside = [], False
    for number, line in enumerate(readme.splitlines(), 1):
        if line.startswith("```"):
            inside = line.strip() == "```sh" if not inside else False
            continue
        if inside and (line.startswith("build/plant ") or line.startswith("printf ")):
            lines.append((number, line))
    return lines


def main():
    plant, source = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    with open(os.path.join(source, "README.md"), encoding="utf-8") as f:
        commands = sh_lines(f.read())
    failures, ran = [], 0
    with tempfile.TemporaryDirectory() as scratch:
        os.makedirs(os.path.join(scratch, "build"))
        os.symlink(plant, os.path.join(scratch, "build", "plant"))
        for linked in ("grammars", "bench"):
            os.symlink(os.path.join(source, linked), os.path.join(scratch, linked))
        for number, line in commands:
            command, _, comment = line.partition("  #")
            if re.match(r"build/plant test\b", command):
                print(f"README.md:{number}: not run (ctest runs the goldens itself): {command.strip()}")
                continue
            if re.match(r"build/plant (view|repl)\b", command):
                print(f"README.md:{number}: not run (interactive): {command.strip()}")
                continue
            if "--seeds 1..1000" in command:
                command = command.replace("--seeds 1..1000", "--seeds 1..12")
                print(f"README.md:{number}: run with --seeds 1..12")
            try:
                done = subprocess.run(["bash", "-c", command], cwd=scratch, capture_output=True,
                                      text=True, timeout=120, env=dict(os.environ, HOME=scratch))
            except subprocess.TimeoutExpired:
                failures.append(f"README.md:{number}: over 120 s: {command.strip()}")
                continue
            ran += 1
            if done.returncode != 0:
                failures.append(f"README.md:{number}: exit {done.returncode}: {command.strip()}\n"
                                f"    {done.stderr.strip()[:400]}")
                continue
            for named in re.findall(r"\bout/[\w.{}-]+", comment):
                if "{" not in named and not os.path.exists(os.path.join(scratch, named)):
                    failures.append(f"README.md:{number}: no {named} after: {command.strip()}")
    print(f"{ran} README commands run, {len(failures)} failed")
    for f in failures:
        print(f)
    if ran < 15:
        print(f"only {ran} commands found in README.md's sh blocks: the parser missed them")
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
