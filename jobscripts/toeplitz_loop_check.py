"""The toeplitz store's time-loop prediction against the loop measured, on the small and medium cases where the
loop's fixed costs (the march's own work a step, the field snapshots, a seismic wave's free field and a massless
footing's correction, a coupled structure) weigh most (issue 41: "the cost model and petsc-ssi estimate know the
new path (time within 30 %)").

    python jobscripts/toeplitz_loop_check.py [OUT [README]]      (OUT default out/bench/toeplitz_loop)

Each case runs REPEAT times (environment, default 3) with -log_view; "predicted" is the run's own first line (``[ssi] time loop: ... predicted
X s``, the model ``petsc-ssi estimate`` prints: bem/toeplitz.py estimate, step_lu_of and loop_rest, and for a
coupled run coupling/cost.py), "measured" the time loop's stage in -log_view (its max over the ranks): the median
of the repeats and their range (this machine's file system stalls a snapshot now and then: one run in 24 of
2026-12-03 took 16 times its prediction, its repeat 1.5-2.5 times). Writes
OUT/toeplitz_loop.csv, prints the table and puts it between <!-- toeplitz-loop:begin/end --> in README (default
jobscripts/README.md). Run on an idle machine (source jobscripts/bench_env.sh first for $PY's environment)."""
import os
import re
import subprocess
import sys
import time

import numpy as np

from petsc_ssi.launch import child_env

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "jobscripts"))
from logview import parse, write_csv, put_block  # noqa: E402

PY = sys.executable
REPEAT = int(os.environ.get("REPEAT", "3"))
MPI = ["mpirun", "--allow-run-as-root", "--oversubscribe"]
BEM = ["-ssi_problem", "bem", "-ssi_mesh_h", "1", "-ssi_mesh_patch", "1,1", "-ssi_dt", "0.0025", "-ssi_t_end", "0.5",
       "-ssi_receivers", "1,0,0", "-ssi_warn_beta", "0", "-ssi_lag_store", "toeplitz"]
LOAD = ["-ssi_load_group", "load", "-ssi_load_p0", "1000"]
SEIS = ["-ssi_seismic", "sv", "-ssi_seismic_angle", "25", "-ssi_seismic_azimuth", "30", "-ssi_seismic_units", "m/s2",
        "-ssi_seismic_taper", "0", "-ssi_seismic_baseline", "none", "-ssi_disp_group", "box:-1,1,-1,1",
        "-ssi_disp_rigid", "massless"]
SSI = ["-ssi_problem", "ssi", "-ssi_cp", "42", "-ssi_cs", "20", "-ssi_rho", "1800", "-ssi_mesh_h", "0.5",
       "-ssi_mesh_patch", "0.5,0.5", "-ssi_fem_box_cells", "4,4,1", "-ssi_fem_box_size", "1,1,0.25",
       "-ssi_fem_box_origin", "-0.5,-0.5,0", "-ssi_fem_E", "3e8", "-ssi_fem_rho", "2000", "-ssi_dt", "0.0125",
       "-ssi_t_end", "1", "-ssi_fem_load_group", "top", "-ssi_fem_load_p0", "1000", "-ssi_fem_load_history", "box",
       "-ssi_fem_load_t0", "0.05", "-ssi_contact", "unilateral", "-ssi_receivers", "1,0,0", "-ssi_warn_beta", "0",
       "-ssi_lag_store", "toeplitz"]


def cases(rec):
    """(name, ranks, options): load on 1 m grids of 4-24 elements a side without and with snapshots every step,
    the oblique SV wave under a massless footing (default stride), the coupled box with contact (stride 1)."""
    out = []
    for s in (4, 8, 16, 24):
        for stride in (0, 1):
            for n in (1, 2):
                out.append((f"load {s}x{s} stride {stride}", n,
                            BEM + LOAD + ["-ssi_mesh_size", f"{s},{s}", "-ssi_output_stride", str(stride)]))
    for s in (8, 16):
        for n in (1, 2):
            out.append((f"SV 25 deg, massless footing {s}x{s}", n,
                        BEM + SEIS + ["-ssi_seismic_record", rec, "-ssi_mesh_size", f"{s},{s}"]))
    for s in (4, 8):
        for n in (1, 2):
            out.append((f"coupled box, contact {2 * s}x{2 * s}", n, SSI + ["-ssi_mesh_size", f"{s},{s}"]))
    return out


PRED = re.compile(r"^\[ssi\] time loop: (\d+) steps .*?predicted ([0-9.e+-]+) s", re.M)


def main(out_dir, readme):
    os.makedirs(out_dir, exist_ok=True)
    rec = os.path.join(out_dir, "pulse.txt")
    t = np.arange(0.0, 1.0 + 1e-9, 0.0025)
    np.savetxt(rec, np.c_[t, np.where(t < 0.2, np.sin(np.pi * t / 0.2) ** 4, 0.0)], header="units: m/s2")
    rows = []
    for name, n, opts in cases(rec):
        tag = re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-") + f"-n{n}"
        log = os.path.join(out_dir, tag + ".log")
        cmd = MPI + ["-n", str(n), PY, "-m", "petsc_ssi"] + opts + [
            "-ssi_output", os.path.join(out_dir, "run.h5"), "-ssi_output_overwrite", "-log_view"]
        t0 = time.perf_counter()
        loops, failed = [], None
        for k in range(REPEAT):
            r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=child_env())
            open(log.replace(".log", f"-{k}.log"), "w").write(r.stdout + r.stderr)
            if r.returncode:
                failed = (r.stderr.strip().splitlines() or ['?'])[-1]
                break
            m = PRED.search(r.stdout)
            stages = parse(r.stdout)["stages"]
            loops.append(next(v for k, v in stages.items() if k.endswith("time loop")))
        if failed:
            print(f"{name} n={n}: failed: {failed}")
            continue
        loop = float(np.median(loops))
        pred = float(m.group(2))
        rows.append({"case": name, "ranks": n, "steps": int(m.group(1)), "predicted_s": round(pred, 4),
                     "measured_s": round(loop, 4), "measured_min_s": round(min(loops), 4),
                     "measured_max_s": round(max(loops), 4), "measured_over_predicted": round(loop / pred, 3),
                     "wall_s": round(time.perf_counter() - t0, 2)})
        print(" | ".join(str(v) for v in rows[-1].values()), flush=True)
    write_csv(os.path.join(out_dir, "toeplitz_loop.csv"), rows)
    ratios = [r["measured_over_predicted"] for r in rows]
    head = (f"| case | ranks | steps | predicted loop [s] | measured loop, median of {REPEAT} [s] | its range [s] | "
            "measured / predicted |\n|---|---|---|---|---|---|---|\n")
    body = "".join(f"| {r['case']} | {r['ranks']} | {r['steps']} | {r['predicted_s']:.3g} | {r['measured_s']:.3g} | "
                   f"{r['measured_min_s']:.3g}-{r['measured_max_s']:.3g} | {r['measured_over_predicted']:.2f} |\n"
                   for r in rows)
    tail = (f"\nmeasured (median) / predicted {min(ratios):.2f}-{max(ratios):.2f} over {len(rows)} cases "
            f"({sum(1 for x in ratios if 1 / 1.3 <= x <= 1.3)} within 30 %); "
            f"`python jobscripts/toeplitz_loop_check.py`, {time.strftime('%Y-%m-%d %H:%M')}\n") if rows else ""
    put_block("toeplitz-loop", head + body + tail, [readme])
    print(tail.strip())


if __name__ == "__main__":
    a = sys.argv[1:]
    main(a[0] if a else os.path.join(ROOT, "out", "bench", "toeplitz_loop"),
         a[1] if len(a) > 1 else os.path.join(ROOT, "jobscripts", "README.md"))
