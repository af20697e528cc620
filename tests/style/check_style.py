#!/usr/bin/env python3
"""Fails when a C++ source file passes 800 lines, a function body passes 120 lines, or a tracked
file cites design notes that are not in the repository (docs/ is the reference).

The house rule (docs/architecture.md, "Files and functions"): a file or function that grows past
these is split by concept. The VM's dispatch loop is the one function allowed to be longer.

A function is found as a line that ends with '{' after a ')' (optionally followed by const,
noexcept, override, a trailing return type or an initializer list) and is not a control
statement; its length runs to the matching closing brace, counted by brace depth outside string
and character literals and comments.

usage: check_style.py REPO_ROOT
"""
import re
import subprocess
import sys

MAX_FILE = 800
MAX_FUNCTION = 120
# (file, function name) pairs allowed to be longer, with the reason.
ALLOWED = {
    ("lang/src/vm.cpp", "execute"): "the VM's dispatch loop: one switch over the opcode table",
}

CONTROL = re.compile(r"^\s*(\}\s*)?(if|else|for|while|switch|do|catch|try)\b")
HEAD = re.compile(r"\)\s*(const\s*)?(noexcept\s*)?(override\s*)?(->\s*[\w:<>,\s\*&]+)?\{\s*$")
NAME = re.compile(r"([~\w:]+(?:<[^()]*>)?)\s*\(")


def strip(line, state):
    """The line without literals and comments; state carries an open /* comment across lines."""
    out, i, n = [], 0, len(line)
    while i < n:
        if state["comment"]:
            j = line.find("*/", i)
            if j < 0:
                return "".join(out)
            state["comment"], i = False, j + 2
            continue
        c = line[i]
        if line.startswith("//", i):
            break
        if line.startswith("/*", i):
            state["comment"], i = True, i + 2
            continue
        if c in "\"'":
            # raw strings are not used in this code base; skip a simple literal
            j = i + 1
            while j < n and line[j] != c:
                j += 2 if line[j] == "\\" else 1
            i = j + 1
            continue
        out.append(c)
        i += 1
    return "".join(out)


def functions(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = f.readlines()
    state = {"comment": False}
    code = [strip(l.rstrip("\n"), state) for l in lines]
    found = []
    i = 0
    while i < len(code):
        text = code[i]
        if HEAD.search(text) and not CONTROL.match(text) and "=" not in text.split("(")[0]:
            # the signature may span lines: take the name from this line or the ones above
            sig = text
            k = i
            while "(" not in sig and k > 0 and i - k < 4:
                k -= 1
                sig = code[k] + " " + sig
            m = NAME.search(sig)
            name = m.group(1).split("::")[-1] if m else "?"
            depth, j = 0, i
            while j < len(code):
                depth += code[j].count("{") - code[j].count("}")
                if depth <= 0:
                    break
                j += 1
            found.append((name, i + 1, j - i + 1))
            i = j + 1
            continue
        i += 1
    return len(lines), found


# Notes the project was started from, which are not part of it: cite docs/ or the paper instead.
OUTSIDE_NOTES = re.compile(r"\b(LANGUAGE|ARCHITECTURE|PLANTS|STYLE)\.md\b|shared/(design|papers)")


def outside_citations(root):
    tracked = subprocess.run(["git", "-C", root, "ls-files"], capture_output=True, text=True,
                             check=True).stdout.split()
    found = []
    for rel in tracked:
        if rel == "tests/style/check_style.py" or "node_modules/" in rel:
            continue
        try:
            with open(f"{root}/{rel}", encoding="utf-8") as f:
                for n, line in enumerate(f, 1):
                    if OUTSIDE_NOTES.search(line):
                        found.append(f"{rel}:{n}: cites design notes outside the repository; cite docs/ or the paper")
        except (UnicodeDecodeError, IsADirectoryError):
            continue
    return found


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else "."
    files = subprocess.run(["git", "-C", root, "ls-files", "*.cpp", "*.hpp", "*.h"],
                           capture_output=True, text=True, check=True).stdout.split()
    problems = []
    for rel in files:
        count, fns = functions(f"{root}/{rel}")
        if count > MAX_FILE:
            problems.append(f"{rel}: {count} lines (at most {MAX_FILE}: split it by concept)")
        for name, line, length in fns:
            if length > MAX_FUNCTION and (rel, name) not in ALLOWED:
                problems.append(f"{rel}:{line}: function '{name}' is {length} lines (at most {MAX_FUNCTION})")
    problems += outside_citations(root)
    for p in problems:
        print(p)
    print(f"check_style: {len(files)} files, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
