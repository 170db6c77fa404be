#!/usr/bin/env python3
"""The table of jobscripts/output_cost.sh: per case and code, the wall time, the output's time
(the SSI_IO event: snapshots, flushes and the final close, the busier rank), the flushes, the
size of the finished file, what is left beside it, and whether the two codes' files are the same
(jobscripts/compare_outputs.py: every dataset and attribute bit for bit, provenance and timings
excepted).

    python jobscripts/output_cost_table.py OUT BEFORE
"""
import os
import sys

import h5py

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import logview  # noqa: E402
import compare_outputs  # noqa: E402


def main(out, before):
    rows = []
    names = sorted({f[:-4] for f in os.listdir(os.path.join(out, "after")) if f.endswith(".log")},
                   key=lambda n: ("medium-every" not in n, "building" in n, n))
    for name in names:
        for code in ("before", "after"):
            log = open(os.path.join(out, code, name + ".log")).read()
            lv = logview.parse(log)
            h5 = os.path.join(out, code, name + ".h5")
            left = sorted(f for f in os.listdir(os.path.join(out, code))
                          if f.startswith(name + ".parts") or f.startswith(name + "_structure.parts"))
            size = os.path.getsize(h5) + (os.path.getsize(h5.replace(".h5", "_structure.h5"))
                                          if os.path.exists(h5.replace(".h5", "_structure.h5")) else 0)
            same = "-"
            if code == "after":
                diffs = []
                for a in (name + ".h5", name + "_structure.h5"):
                    pa, pb = os.path.join(out, "before", a), os.path.join(out, "after", a)
                    if os.path.exists(pa):
                        with h5py.File(pa, "r") as fa, h5py.File(pb, "r") as fb:
                            diffs += compare_outputs.compare(fa, fb)
                same = "yes" if not diffs else f"no ({len(diffs)}: {diffs[0][:80]})"
            ev = lv["events"].get("SSI_IO", (0, 0.0))
            rows.append({"case": name, "code": before if code == "before" else "this checkout",
                         "wall_s": f"{lv['total_s']:.2f}", "output_s": f"{ev[1]:.3f}", "output_events": ev[0],
                         "file_MB": f"{size / 1e6:.2f}", "left_beside": " ".join(left) or "-",
                         "same_as_before": same})
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    logview.write_csv(os.path.join(HERE, "results", "output_cost.csv"), rows)
    head = ("| case | code | wall [s] | output: SSI_IO [s] (events) | files [MB] | left beside | same as before |\n"
            "|---|---|---|---|---|---|---|\n")
    body = "".join(f"| {r['case']} | {r['code']} | {r['wall_s']} | {r['output_s']} ({r['output_events']}) | "
                   f"{r['file_MB']} | {r['left_beside']} | {r['same_as_before']} |\n" for r in rows)
    logview.put_block("output_cost", head + body, [os.path.join(HERE, "README.md")])
    print(head + body)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
