#!/usr/bin/env python3
"""Samples per function of a py-spy raw profile (jobscripts/spy_profile.sh): inclusive counts (the samples
whose stack holds the function, once a stack), as seconds at the sampling rate and as a share of the samples.

    python jobscripts/spy_table.py PROF.txt [--filter NAME] [--top N] [--rate 50]

``--filter``: only the stacks through a function whose name holds NAME (e.g. VecScatterCreate: what calls it
and what it calls); line numbers are dropped, so a function's lines count together."""
import argparse
import collections
import re


def table(path, filt=None):
    """(total samples, Counter {function: samples}) of a py-spy raw file."""
    inc, tot = collections.Counter(), 0
    with open(path) as fh:
        for line in fh:
            line = line.rstrip()
            if not line or " " not in line:
                continue
            stack, n = line.rsplit(" ", 1)
            frames = [re.sub(r":\d+\)", ")", f) for f in stack.split(";")]
            if filt and not any(filt in f for f in frames):
                continue
            n = int(n)
            tot += n
            for f in set(frames):
                inc[f] += n
    return tot, inc


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("prof")
    ap.add_argument("--filter", default=None)
    ap.add_argument("--top", type=int, default=50)
    ap.add_argument("--rate", type=float, default=50.0, help="py-spy's samples a second (spy_profile.sh: 50)")
    a = ap.parse_args()
    tot, inc = table(a.prof, a.filter)
    print(f"{tot} samples ({tot / a.rate:.1f} s at {a.rate:g} a second)" + (f" through '{a.filter}'" if a.filter else ""))
    print("| samples | seconds | share of these samples | function (file) |")
    print("|---|---|---|---|")
    named = [(f, v) for f, v in inc.most_common() if not f.startswith("0x")]   # (unresolved native frames)
    for f, v in named[:a.top]:
        print(f"| {v} | {v / a.rate:.1f} | {100.0 * v / max(tot, 1):.1f} % | {f[:140]} |")


if __name__ == "__main__":
    main()
