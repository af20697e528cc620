#!/usr/bin/env python3
"""Fails when a document misses a name from one of plant's tables.

    tests/docs/check_names.py PLANT SOURCE_DIR

Every name `plant help TOPIC --names` prints must appear as code (between backticks) in the
document that describes it. A new built-in, turtle symbol, hook, setting, operator, environment method, REPL command
or output format therefore cannot land without a line in the docs. Adding a topic is one row in TOPICS.
"""
import re
import subprocess
import sys

# (what `plant help` is given, the document, how a name must appear in one of its code spans)
#   word:   as a whole word anywhere in the span (`uniform(a,b)`, `sin cos tan`)
#   prefix: at the start of the span, not followed by a letter or digit (`:step [N]`, `.glb`)
TOPICS = [
    (["builtins"], "docs/language.md", "word"),
    (["turtle"], "docs/language.md", "prefix"),
    (["hooks"], "docs/language.md", "word"),
    (["settings"], "docs/language.md", "word"),
    (["operators"], "docs/language.md", "word"),
    (["env"], "docs/language.md", "word"),  # the kinds; their methods below
    (["repl"], "README.md", "prefix"),
    (["formats"], "README.md", "prefix"),
]


def names(plant, args):
    out = subprocess.run([plant, "help", *args, "--names"], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"plant help {' '.join(args)} --names failed ({out.returncode}): {out.stderr.strip()}")
    return [n for n in out.stdout.splitlines() if n]


def code_spans(text):
    # inline code only: fenced blocks are examples, not the place a name is documented
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    return re.findall(r"`([^`\n]+)`", text)


def documented(name, spans, how):
    if how == "word":
        pattern = re.compile(r"(?<![\w.])" + re.escape(name) + r"(?!\w)")
        return any(pattern.search(s) for s in spans)
    return any(s.startswith(name) and not s[len(name):len(name) + 1].isalnum() for s in spans)


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: check_names.py PLANT SOURCE_DIR")
    plant, root = sys.argv[1], sys.argv[2]
    topics = list(TOPICS)
    for kind in names(plant, ["env"]):
        topics.append((["env", kind], "docs/language.md", "word"))
    missing = checked = 0
    for args, doc, how in topics:
        with open(f"{root}/{doc}", encoding="utf-8") as f:
            spans = code_spans(f.read())
        for name in names(plant, args):
            checked += 1
            if not documented(name, spans, how):
                missing += 1
                print(f"FAIL {doc} does not mention `{name}` (plant help {' '.join(args)})")
    print(f"{checked - missing} of {checked} names documented")
    if checked == 0 or missing:
        sys.exit(1)


main()
