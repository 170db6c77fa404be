#!/usr/bin/env python3
"""Parse PETSc -log_view (and -memory_view) output into a dict of numbers.

Usage as a module: ``parse(text) -> {"total_s", "stages": {name: s},
"events": {name: (count, max_s)}, "peak_rss_bytes", "ranks"}``. Used by the
benchmark and scaling scripts so that every number in a README table comes
from a log of a run that the script itself made.
"""
import re
import sys


def parse(text):
    out = {"stages": {}, "events": {}, "total_s": None, "peak_rss_bytes": None, "ranks": None}
    # "with 2 processors" to PETSc 3.21, "with 2 processes" from 3.22 (commit 5c78b439518)
    m = re.search(r"with (\d+) (?:processors?|processes|process)\b", text)
    if m:
        out["ranks"] = int(m.group(1))
    m = re.search(r"^Time \(sec\):\s+(\S+)\s+(\S+)?\s*(\S+)", text, re.M)
    if m:
        out["total_s"] = float(m.group(1))
    # Summary of Stages: "  k:  Name: time %  flop % ..."
    sec = text.split("Summary of Stages:", 1)
    if len(sec) == 2:
        for line in sec[1].splitlines()[3:]:
            mm = re.match(r"\s*\d+:\s+(.+?):\s+(\S+)\s+\S+%", line)
            if not mm:
                if line.strip() == "" or line.startswith("---"):
                    break
                continue
            out["stages"][mm.group(1).strip()] = float(mm.group(2))
    # Event lines: "Name  Count Ratio  Time(max) Ratio ..."
    for line in text.splitlines():
        mm = re.match(r"^(SSI_\w+|MatMult|MatMultAdd|MatLUFactorNum|MatLUFactorSym|KSPSolve|PCSetUp|MatAssemblyEnd)\s+(\d+)\s+\S+\s+(\S+)\s", line)
        if mm:
            name = mm.group(1)
            prev = out["events"].get(name, (0, 0.0))
            out["events"][name] = (prev[0] + int(mm.group(2)), prev[1] + float(mm.group(3)))
    m = re.search(r"Maximum \(over computational time\) process memory:\s+total\s+(\S+)\s+max\s+(\S+)", text)
    if m:
        out["peak_rss_bytes"] = float(m.group(1))
        out["peak_rss_max_rank_bytes"] = float(m.group(2))
    return out


if __name__ == "__main__":
    import json
    print(json.dumps(parse(open(sys.argv[1]).read()), indent=1))


def write_csv(path, rows):
    """Rows (dicts) to a CSV whose columns are every key in first-seen order."""
    import csv
    import os
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, keys)
        w.writeheader()
        w.writerows(rows)


def put_block(tag, block, paths):
    """Replace the text between <!-- tag:begin --> and <!-- tag:end --> in each file that has them."""
    begin, end = f"<!-- {tag}:begin -->", f"<!-- {tag}:end -->"
    for path in paths:
        text = open(path).read()
        if begin in text and end in text:
            text = text[:text.index(begin) + len(begin)] + "\n" + block + text[text.index(end):]
            open(path, "w").write(text)
