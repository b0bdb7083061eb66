#!/usr/bin/env python3
"""Functions longer than a limit in the library crates' non-test code.

A function's length is the lines from its `fn` line to its closing brace.
Test code is left out (`tests.rs`, `tests/`, `#[cfg(test)]` modules). A
function preceded within eight lines by a comment saying "one piece" (or "one loop")
is listed as explained.

Usage: scripts/long_functions.py [--limit 120] [CRATE ...]
Run from the repository root. Exits 1 when an unexplained function is over
the limit.
"""
import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LIBRARIES = ["sahara-kd", "sahara-render", "sahara-readers", "sahara-formats"]
FN = re.compile(r"^\s*(?:pub(?:\([\w:]+\))?\s+)?(?:const\s+)?(?:unsafe\s+)?fn\s+(\w+)")


def test_ranges(lines):
    """Line ranges of `#[cfg(test)]` items."""
    out, i = [], 0
    while i < len(lines):
        if lines[i].strip() == "#[cfg(test)]":
            end = block_end(lines, i + 1)
            out.append((i, end))
            i = end + 1
        else:
            i += 1
    return out


def block_end(lines, start):
    """The line closing the first brace block opened at or after `start`."""
    depth, opened = 0, False
    for j in range(start, len(lines)):
        code = lines[j].split("//")[0]
        depth += code.count("{") - code.count("}")
        opened |= "{" in code
        if opened and depth <= 0:
            return j
        if not opened and code.rstrip().endswith(";"):
            return j
    return len(lines) - 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=int, default=120)
    ap.add_argument("crates", nargs="*", default=LIBRARIES)
    a = ap.parse_args()
    unexplained = 0
    for crate in a.crates:
        src = os.path.join(ROOT, "crates", crate, "src")
        for dirpath, dirnames, filenames in os.walk(src):
            dirnames[:] = sorted(d for d in dirnames if d != "tests")
            for name in sorted(filenames):
                if not name.endswith(".rs") or name == "tests.rs":
                    continue
                path = os.path.join(dirpath, name)
                lines = open(path, encoding="utf-8").read().split("\n")
                skip = test_ranges(lines)
                for i, line in enumerate(lines):
                    m = FN.match(line)
                    if not m or any(s <= i <= e for s, e in skip):
                        continue
                    end = block_end(lines, i)
                    n = end - i + 1
                    if n > a.limit:
                        why = any(re.search(r"one (piece|loop)", l, re.I) for l in lines[max(0, i - 8):i])
                        unexplained += not why
                        rel = os.path.relpath(path, ROOT)
                        print(f"{n:4}  {rel}:{i + 1}  {m.group(1)}{'  (explained)' if why else ''}")
    sys.exit(1 if unexplained else 0)


if __name__ == "__main__":
    main()
