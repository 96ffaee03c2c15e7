#!/usr/bin/env python3
"""Compare two `linkage run` output trees file by file: byte-identical, except for the timing
fields of summary.json (`seconds` per step and `phases`), which are dropped before comparing,
and the wall times (`0.123 s`) the HTML report's pages (`index.html`) show.

    python3 .ci/same_outputs.py BEFORE_DIR AFTER_DIR

Exits 0 when every file matches, 1 (listing the differences) otherwise.
"""
import json
import os
import re
import sys

TIMING = {"seconds", "phases"}


def strip(value):
    if isinstance(value, dict):
        return {k: strip(v) for k, v in value.items() if k not in TIMING}
    if isinstance(value, list):
        return [strip(v) for v in value]
    return value


def files(root):
    out = set()
    for folder, _, names in os.walk(root):
        for name in names:
            out.add(os.path.relpath(os.path.join(folder, name), root))
    return out


def main():
    before, after = sys.argv[1], sys.argv[2]
    a, b = files(before), files(after)
    problems = [f"only in {before}: {p}" for p in sorted(a - b)]
    problems += [f"only in {after}: {p}" for p in sorted(b - a)]
    same = 0
    for path in sorted(a & b):
        x = open(os.path.join(before, path), "rb").read()
        y = open(os.path.join(after, path), "rb").read()
        if os.path.basename(path) == "summary.json":
            x, y = strip(json.loads(x)), strip(json.loads(y))
        if os.path.basename(path) == "index.html":
            x, y = (re.sub(rb"\d+\.\d{3} s", b"", v) for v in (x, y))
        if x != y:
            problems.append(f"differs: {path}")
        else:
            same += 1
    for p in problems:
        print(p)
    print(f"{same} files identical, {len(problems)} problems")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
