#!/usr/bin/env python3
"""Mutation smoke test: no input makes plant crash or hang.

Takes the repository's grammars, mutates each copy a few times (inserted tokens, deleted and
duplicated spans, replaced characters), and runs `plant check`, `plant derive` and `plant run`
on the result. Any exit by signal, exit status of 128 or more, sanitizer report or run past the
time limit is a failure; the offending input is kept in the output directory. Diagnostics and
ordinary error statuses are the expected outcome for most mutants.

  mutate.py PLANT [--seed N] [--count N] [--seconds S] [--timeout S] [--out DIR]

The seed fixes the mutants, so a failure reproduces. With --seconds, it stops starting new
mutants once that much time has passed (the count is then an upper bound): the sanitizer job
gives it a time budget this way (docs/testing.md). Built with -fsanitize=address,undefined,
plant also reports memory errors that do not crash.
"""
import argparse
import os
import pathlib
import random
import shutil
import subprocess
import sys
import tempfile
import time

TOKENS = list("()[]{}<>;:,.+-*/^=!?&|@#'\"\\$%~`\n\t 0123456789") + [
    "->", "=>", "<<", ">>", "if", "module", "axiom", "param", "use", "env", "group", "end",
    "def", "return", "1e309", "nan", "-0", "999999999999", "(((((", ")))))", "\x00", "\xff", "é",
]


def mutate(rng: random.Random, s: str) -> str:
    for _ in range(rng.randint(1, 6)):
        op = rng.random()
        i = rng.randint(0, len(s))
        if op < 0.35:
            s = s[:i] + rng.choice(TOKENS) + s[i:]
        elif op < 0.65:
            s = s[:i] + s[i + rng.randint(1, 8):]
        elif op < 0.85:
            a, b = sorted((i, rng.randint(0, len(s))))
            s = s[:i] + s[a:min(b, a + 80)] + s[i:]
        else:
            s = s[:i] + rng.choice(TOKENS) + s[i + 1:]
    return s


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("plant")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--count", type=int, default=150)
    ap.add_argument("--seconds", type=float, default=None, help="time budget: start no mutant after this many seconds")
    ap.add_argument("--timeout", type=float, default=30, help="seconds one command may run (default 30)")
    ap.add_argument("--out", default=None, help="where failing inputs are kept (default: a temporary directory)")
    args = ap.parse_args()
    plant = os.path.realpath(args.plant)
    repo = pathlib.Path(__file__).resolve().parents[2]
    files = sorted(repo.glob("grammars/**/*.plant")) + sorted(repo.glob("tests/scripts/**/*.plant"))
    sources = [f.read_text(encoding="utf-8", errors="replace") for f in files]
    if not sources:
        print("mutate.py: no grammars found", file=sys.stderr)
        return 1
    rng = random.Random(args.seed)
    out = pathlib.Path(args.out or tempfile.mkdtemp(prefix="plant-fuzz-"))
    out.mkdir(parents=True, exist_ok=True)
    work = pathlib.Path(tempfile.mkdtemp(prefix="plant-fuzz-work-"))
    case = work / "case.plant"
    bad = 0
    done = 0
    start = time.monotonic()
    for k in range(args.count):
        if args.seconds is not None and time.monotonic() - start > args.seconds:
            break
        done += 1
        text = mutate(rng, rng.choice(sources))
        case.write_text(text, encoding="utf-8", errors="replace")
        commands = [
            [plant, "check", str(case)],
            [plant, "derive", "-n", "4", "--max-modules", "200000", str(case)],
            [plant, "run", str(case), "-n", "3", "-o", str(work / "o.glb"), "-o", str(work / "o.png")],
        ]
        for cmd in commands:
            try:
                r = subprocess.run(cmd, capture_output=True, timeout=args.timeout, cwd=work)
            except subprocess.TimeoutExpired:
                reason = f"ran past {args.timeout:g} s"
            else:
                err = r.stderr.decode("utf-8", "replace")
                if r.returncode < 0 or r.returncode >= 128:
                    reason = f"exit status {r.returncode}"
                elif "Sanitizer" in err or "runtime error:" in err:
                    reason = "sanitizer report"
                else:
                    continue
            bad += 1
            kept = out / f"mutant_{args.seed}_{k}.plant"
            kept.write_text(text, encoding="utf-8", errors="replace")
            print(f"FAIL plant {cmd[1]} on {kept}: {reason}")
    print(f"{done} mutants, 3 commands each, in {time.monotonic() - start:.0f} s: {bad} failed")
    shutil.rmtree(work, ignore_errors=True)
    if not bad and args.out is None:
        shutil.rmtree(out, ignore_errors=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
