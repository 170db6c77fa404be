#!/usr/bin/env python3
"""Tables of runs/structures/README.md, written from the CSVs (no number is typed by hand).

    python runs/structures/report.py                     # README tables from the CSVs
    python runs/structures/report.py --logs out/structures-bench
        # first parse the benchmark's logs (runs/structures/bench.sh) into bench.csv and the
        # profile (cProfile of one run) into profile.csv, then rewrite the README tables

Logs of a run OUT/e<elem>-np<ranks>-r<k>[-a|-b].*: ``.log`` -log_view (times: the "max over
ranks" column of each event), ``.out`` (the application's lines: nodes, dofs; -memory_view;
MUMPS statistics from -ssi_fem_mat_mumps_icntl_4 2), ``.wall.time`` (/usr/bin/time -v of mpirun),
``.rank<r>.time`` (/usr/bin/time -v of rank r: maximum resident set size). Ranks ``1x2``: two
independent 1-rank jobs run at the same time (control), jobs a and b.

README markers: <!-- bench:begin/end --> (benchmark, scaling from 1 to 2 ranks, profile) and
<!-- convergence:begin/end --> (obstacle course, from convergence.csv of convergence.py).
"""
import argparse
import csv
import glob
import os
import re
import statistics

HERE = os.path.dirname(os.path.abspath(__file__))
README = os.path.join(HERE, "README.md")
BENCH_CSV = os.path.join(HERE, "bench.csv")
PROFILE_CSV = os.path.join(HERE, "profile.csv")
CONV_CSV = os.path.join(HERE, "convergence.csv")

EVENTS = {"FEM_assembly": "assembly", "FEM_static": "static", "PCSetUp": "pcsetup",
          "MatLUFactorSym": "lu_sym", "MatLUFactorNum": "lu_num", "MatSolve": "matsolve",
          "KSPSolve": "kspsolve"}
NAME = re.compile(r"e(?P<elem>[0-9.]+)-np(?P<ranks>\d+(?:x\d+)?)-r(?P<rep>\d+)(?:-(?P<job>[ab]))?\.log$")
FIELDS = ["elem_m", "ranks", "repeat", "job", "nodes", "dofs", "fixed", "shells", "frames",
          "setup_s", "assembly_s", "assembly_ratio", "pcsetup_s", "lu_sym_s", "lu_num_s", "matsolve_s",
          "kspsolve_s", "static_s", "total_s", "wall_s", "startup_s", "rss_rank_max_MB", "rss_sum_MB",
          "memview_rank_max_MB", "mumps_alloc_MB", "factor_entries", "mumps_flops", "max_u_m", "other_load",
          "steal", "code", "in_table", "log"]


# ------------------------------------------------------------------ parsing the logs
def _time_file(path):
    """(elapsed s, max RSS kB) of a /usr/bin/time -v file."""
    text = open(path).read()
    m = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", text)
    secs = 0.0
    for part in m.group(1).split(":"):
        secs = 60 * secs + float(part)
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1))
    return secs, rss


def _cpu_time(path):
    """user + system CPU seconds of a /usr/bin/time -v file (mpirun's: its ranks included)."""
    text = open(path).read()
    return sum(float(re.search(rf"{k} time \(seconds\): (\S+)", text).group(1)) for k in ("User", "System"))


def _other_load(base, wall):
    """(other jobs' busy cores, steal cores) during a run: the machine's busy CPU time from
    /proc/stat before/after minus the run's own CPU time (mpirun and its ranks), over the wall time."""
    path = base + ".stat"
    if not (os.path.exists(path) and os.path.exists(base + ".wall.time")) or not wall:
        return "", ""
    a, b = [list(map(int, line.split()[1:])) for line in open(path).read().splitlines()[:2]]
    d = [y - x for x, y in zip(a, b)]
    tick = os.sysconf("SC_CLK_TCK")
    busy = (d[0] + d[1] + d[2] + d[5] + d[6]) / tick
    steal = d[7] / tick if len(d) > 7 else 0.0
    own = _cpu_time(base + ".wall.time")
    return round(max(busy - own, 0.0) / wall, 3), round(steal / wall, 3)


def parse_run(log):
    m = NAME.search(os.path.basename(log))
    if not m:
        return None
    base = log[:-4]
    row = {"elem_m": m["elem"], "ranks": m["ranks"], "repeat": int(m["rep"]), "job": m["job"] or "",
           "log": os.path.relpath(log, os.path.join(HERE, "..", ".."))}
    text = open(log).read()
    row["total_s"] = float(re.search(r"^Time \(sec\):\s+(\S+)", text, re.M).group(1))
    for ev, key in EVENTS.items():
        hit = re.search(rf"^{ev}\s+(\d+)\s+\S+\s+(\S+)\s+(\S+)", text, re.M)
        row[f"{key}_s"] = float(hit.group(2)) if hit else 0.0
        if ev == "FEM_assembly":
            row["assembly_ratio"] = float(hit.group(3)) if hit else ""
    row["setup_s"] = row["total_s"] - row["assembly_s"] - row["static_s"]
    out = open(base + ".out").read()
    d = re.search(r"\[fem\] mesh \S+: (\d+) nodes .*?, (\d+) shell, (\d+) frame, (\d+) dofs, (\d+) fixed", out)
    row.update(nodes=int(d.group(1)), shells=int(d.group(2)), frames=int(d.group(3)), dofs=int(d.group(4)),
               fixed=int(d.group(5)))
    u = re.search(r"max \|u_i\| = (\S+)", out)
    row["max_u_m"] = float(u.group(1)) if u else ""
    mv = re.search(r"Maximum \(over computational time\) process memory:\s+total\s+(\S+)\s+max\s+(\S+)", out)
    row["memview_rank_max_MB"] = round(float(mv.group(2)) / 1e6, 1) if mv else ""
    a = re.search(r"Memory allocated, total in Mbytes\s+\(INFOG\(19\)\):\s+(\d+)", out)
    row["mumps_alloc_MB"] = int(a.group(1)) if a else ""
    f = re.search(r"INFOG\(29\)\s+Number of entries in factors\s+=\s+(\d+)", out)
    row["factor_entries"] = int(f.group(1)) if f else ""
    fl = re.search(r"RINFOG\(1\) Operations during elimination \(estim\)\s*=\s*(\S+)", out)
    row["mumps_flops"] = float(fl.group(1).replace("D", "E")) if fl else ""
    wall = base + ".wall.time"
    row["wall_s"] = _time_file(wall)[0] if os.path.exists(wall) else ""
    row["startup_s"] = round(row["wall_s"] - row["total_s"], 3) if row["wall_s"] != "" else ""
    row["other_load"], row["steal"] = _other_load(base, row["wall_s"])
    row["code"] = open(base + ".rev").read().strip() if os.path.exists(base + ".rev") else ""
    rss = [_time_file(p)[1] for p in sorted(glob.glob(base + ".rank*.time"))]
    row["rss_rank_max_MB"] = round(max(rss) * 1024 / 1e6, 1)     # kB (KiB) -> MB
    row["rss_sum_MB"] = round(sum(rss) * 1024 / 1e6, 1)
    for k in ("setup_s",):
        row[k] = round(row[k], 4)
    return row


def parse_logs(directory):
    rows = [r for r in (parse_run(p) for p in sorted(glob.glob(os.path.join(directory, "e*.log")))) if r]
    rows.sort(key=lambda r: (-float(r["elem_m"]), r["ranks"], r["repeat"], r["job"]))
    # The application may change while the benchmark runs (other engineers commit): only the runs
    # of the version of the last run enter the tables (same .rev; without .rev files: the same
    # solution max |u| as the last run of that mesh, to 1e-9). The others stay in bench.csv.
    last = max(rows, key=lambda r: os.path.getmtime(os.path.join(HERE, "..", "..", r["log"])))
    for r in rows:
        if last["code"]:
            r["in_table"] = int(r["code"] == last["code"])
        else:
            same = [x for x in rows if x["elem_m"] == r["elem_m"]]
            ref = max(same, key=lambda x: os.path.getmtime(os.path.join(HERE, "..", "..", x["log"])))["max_u_m"]
            r["in_table"] = int(abs(r["max_u_m"] - ref) <= 1e-9 * abs(ref))
    with open(BENCH_CSV, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    print(f"[report] {len(rows)} runs -> {BENCH_CSV}")
    load = os.path.join(directory, "load.txt")
    return rows, (open(load).read() if os.path.exists(load) else "")


# ------------------------------------------------------------------ the profile
PROFILE_ITEMS = [  # (label, file suffix or '', function name or substring)
    ("whole run under cProfile", "petsc_ssi/app/cli.py", "main"),
    ("petsc4py initialise", "petsc4py/__init__.py", "init"),
    ("build_model: set-up + assembly", "fem/model.py", "build_model"),
    ("load_mesh: read on rank 0, renumber, broadcast", "fem/mesh.py", "load_mesh"),
    ("gmsh reader (mesh/gmsh.py read)", "mesh/gmsh.py", "read"),
    ("structure_from_model: parts, shell-cell dict per group", "fem/mesh.py", "structure_from_model"),
    ("check_structure: coincident nodes (cKDTree), element checks", "fem/mesh.py", "check_structure"),
    ("renumber_rcm", "fem/mesh.py", "renumber_rcm"),
    ("DofMap._section: PETSc Section node by node (built twice)", "fem/dofmap.py", "_section"),
    ("DofMap.__init__ (first Section, getOffset per node)", "fem/dofmap.py", "__init__"),
    ("DofMap.set_fixed (Section rebuilt with constraints)", "fem/dofmap.py", "set_fixed"),
    ("inputs: fixed dofs, loads, receivers", "fem/model.py", "_inputs"),
    ("describe_parts: mass report", "fem/model.py", "describe_parts"),
    ("assemble (= event FEM_assembly)", "fem/assembly.py", "assemble"),
    ("local_stiffness_csr", "fem/assembly.py", "local_stiffness_csr"),
    ("shell element stiffness (vectorised numpy)", "fem/elements/shell.py", "stiffness"),
    ("frame element stiffness", "fem/elements/frame.py", "stiffness"),
    ("scipy COO -> CSR (tocsr)", "scipy/sparse/_coo.py", "tocsr"),
    ("scipy CSR sort_indices", "scipy/sparse/_compressed.py", "sort_indices"),
    ("local_lumped_mass", "fem/assembly.py", "local_lumped_mass"),
    ("csr_to_petsc: preallocation, setValuesCSR, MatAssembly", "fem/assembly.py", "csr_to_petsc"),
    ("static_solve (inside event FEM_static)", "fem/static.py", "static_solve"),
    ("KSP set-up: MUMPS analysis + factorisation", "fem/integrators.py", "setup_or_fail"),
    ("KSP solve (MUMPS triangular solves)", "~", "<method 'solve' of 'petsc4py.PETSc.KSP' objects>"),
]


def parse_profile(directory):
    import pstats
    rows = []
    for path in sorted(glob.glob(os.path.join(directory, "profile-e*.prof"))):
        elem = re.search(r"profile-e([0-9.]+)\.prof", path).group(1)
        st = pstats.Stats(path).stats
        for label, fsuf, func in PROFILE_ITEMS:
            hits = [(k, v) for k, v in st.items() if k[2] == func and k[0].replace("\\", "/").endswith(fsuf)]
            if not hits:
                continue
            calls = sum(v[1] for _, v in hits)
            own = sum(v[2] for _, v in hits)
            cum = max(v[3] for _, v in hits)
            rows.append(dict(elem_m=elem, item=label, function=f"{hits[0][0][0].split('/')[-1]}:{func}",
                             calls=calls, cumulative_s=round(cum, 4), own_s=round(own, 4)))
    if rows:
        with open(PROFILE_CSV, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        print(f"[report] profile -> {PROFILE_CSV}")
    return rows


# ------------------------------------------------------------------ tables
def _read(path):
    if not os.path.exists(path):
        return []
    with open(path) as fh:
        return list(csv.DictReader(fh))


def _f(x):
    return float(x) if x not in ("", None) else float("nan")


def _g(x, nd=3):
    return "" if x != x else f"{x:.{nd}g}"


CLEAN = 0.25     # a run is clean when other jobs kept at most this many cores busy (column other load)
TIMES = ("setup_s", "assembly_s", "pcsetup_s", "lu_sym_s", "lu_num_s", "matsolve_s", "kspsolve_s", "static_s",
         "total_s", "wall_s", "startup_s")


def medians(rows):
    """{(elem, ranks): {field: value}}: times (TIMES) the minimum over the repeats (best of N: the
    machine is shared, other jobs only ever slow a run down), everything else the median;
    'total_median' the median of total_s, 'n' the runs and how many were clean (other load
    <= CLEAN cores; CLEAN + 1 for the control, whose twin job is expected)."""
    groups = {}
    for r in rows:
        if str(r.get("in_table", "1")) in ("0", "False"):
            continue
        groups.setdefault((r["elem_m"], r["ranks"]), []).append(r)
    out = {}
    for key, rs in groups.items():
        limit = CLEAN + (1.0 if "x" in key[1] else 0.0)
        clean = [r for r in rs if r.get("other_load") not in ("", None) and _f(r["other_load"]) <= limit]
        med = {"n": f"{len(rs)} ({len(clean)} clean)"}
        for k in FIELDS:
            if k in ("elem_m", "ranks", "job", "log", "code"):
                continue
            vals = [_f(r[k]) for r in rs if r[k] not in ("", None)]
            med[k] = (min(vals) if k in TIMES else statistics.median(vals)) if vals else float("nan")
        med["total_median"] = statistics.median(_f(r["total_s"]) for r in rs)
        med["elem_m"], med["ranks"] = key
        out[key] = med
    return out


RANK_LABEL = {"1": "1", "2": "2", "1x2": "1 (x2 jobs at once)"}


def bench_tables(rows, prof, load):
    med = medians(rows)
    keys = sorted(med, key=lambda k: (-float(k[0]), {"1": 0, "2": 1}.get(k[1], 2)))
    head = ("| elem [m] | nodes | dofs | ranks | runs | set-up [s] | assembly [s] | assembly max/min | "
            "MUMPS analysis + factor [s] | of which numeric [s] | solves [s] | FEM_static [s] | "
            "-log_view total [s] | total median [s] | wall [s] | RSS max rank [MB] | RSS all ranks [MB] | MUMPS alloc [MB] | "
            "factor entries [1e6] | max abs u [mm] | other load [cores] |")
    lines = ["Times: the minimum over the repeats of each case (best of N; `runs`: how many, and how many were "
             f"clean, i.e. other jobs kept at most {CLEAN} cores busy, the control's twin job not counted); "
             "`total median`: the median of the -log_view total, for the spread; memory and other load: medians. "
             "Every run is a row of `bench.csv`; runs made with an earlier version of the application than the "
             f"last run (`in_table` 0: {sum(str(r.get('in_table', '1')) in ('0', 'False') for r in rows)} runs) "
             "are left out.", "", head,
             "|" + "---|" * (head.count("|") - 1)]
    for k in keys:
        m = med[k]
        lines.append(
            f"| {m['elem_m']} | {int(m['nodes'])} | {int(m['dofs'])} | {RANK_LABEL.get(m['ranks'], m['ranks'])} | "
            f"{m['n']} | {_g(m['setup_s'])} | {_g(m['assembly_s'])} | {_g(m['assembly_ratio'])} | "
            f"{_g(m['pcsetup_s'])} | {_g(m['lu_num_s'])} | {_g(m['matsolve_s'])} | {_g(m['static_s'])} | "
            f"{_g(m['total_s'])} | {_g(m['total_median'])} | {_g(m['wall_s'])} | {m['rss_rank_max_MB']:.0f} | {m['rss_sum_MB']:.0f} | "
            f"{_g(m['mumps_alloc_MB'])} | {_g(m['factor_entries'] / 1e6)} | {_g(1e3 * m['max_u_m'], 4)} | "
            f"{_g(m['other_load'], 2)} |")
    # 1 -> 2 ranks
    lines += ["", "From 1 to 2 ranks (ratios of the values above; > 1 = faster or smaller on 2 ranks; "
              "`control`: the 1-rank run alone / the same run while a second 1-rank job runs):", "",
              "| elem [m] | dofs | assembly t1/t2 | set-up t1/t2 | MUMPS analysis + factor t1/t2 | "
              "solves t1/t2 | total t1/t2 | wall t1/t2 | RSS max rank 1/2 | RSS all ranks 1/2 | "
              "control: assembly alone / busy | control: total alone / busy |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for e in sorted({k[0] for k in keys}, key=lambda s: -float(s)):
        a, b, c = med.get((e, "1")), med.get((e, "2")), med.get((e, "1x2"))
        if not (a and b):
            continue
        r = lambda k, x=a, y=b: _g(x[k] / y[k]) if y and y[k] else ""   # noqa: E731
        lines.append(f"| {e} | {int(a['dofs'])} | {r('assembly_s')} | {r('setup_s')} | {r('pcsetup_s')} | "
                     f"{r('matsolve_s')} | {r('total_s')} | {r('wall_s')} | {r('rss_rank_max_MB')} | "
                     f"{r('rss_sum_MB')} | {r('assembly_s', a, c) if c else ''} | {r('total_s', a, c) if c else ''} |")
    lines += ["", "Key figures (computed from the values above):", ""] + summary(med)
    if prof:
        lines += ["", "Where one 1-rank run of the {} m model spends its time (cProfile, cumulative seconds of "
                  "each function including what it calls; indented items are inside the one above; "
                  "`profile.csv`):".format(prof[0]["elem_m"]), "",
                  "| item | function | calls | cumulative [s] | own [s] |", "|---|---|---|---|---|"]
        inner = {"gmsh reader", "structure_from_model", "check_structure", "renumber_rcm", "local_stiffness_csr",
                 "local_lumped_mass", "csr_to_petsc", "KSP set-up", "KSP solve"}
        inner2 = {"shell element", "frame element", "scipy COO", "scipy CSR"}
        for p in prof:
            ind = "&nbsp;&nbsp;&nbsp;&nbsp;" if any(p["item"].startswith(s) for s in inner2) else \
                "&nbsp;&nbsp;" if any(p["item"].startswith(s) for s in inner) else ""
            lines.append(f"| {ind}{p['item']} | `{p['function']}` | {p['calls']} | {_g(_f(p['cumulative_s']))} | "
                         f"{_g(_f(p['own_s']))} |")
    if load.strip():
        lines += ["", "Machine load around the benchmark (`uptime`, from the logs' `load.txt`):", "", "```",
                  load.strip(), "```"]
    return "\n".join(lines)


def summary(med):
    """Bullets of derived numbers: where the time goes, memory per dof, growth exponents."""
    import math
    out = []
    one = sorted([m for k, m in med.items() if k[1] == "1"], key=lambda m: m["dofs"])
    two = {m["elem_m"]: m for k, m in med.items() if k[1] == "2"}
    for m in one:
        t = m["total_s"]
        out.append(f"- {int(m['dofs'])} dofs, 1 rank: -log_view total {t:.3g} s = set-up {100 * m['setup_s'] / t:.0f}% + "
                   f"assembly {100 * m['assembly_s'] / t:.0f}% + MUMPS analysis and factorisation "
                   f"{100 * m['pcsetup_s'] / t:.0f}% + solves {100 * m['matsolve_s'] / t:.0f}% (+ elimination of the fixed "
                   f"dofs and vectors {100 * max(m['static_s'] - m['pcsetup_s'] - m['matsolve_s'], 0) / t:.0f}%); "
                   f"the process start (python imports, MPI) adds {m['wall_s'] - t:.2g} s of wall time; "
                   f"RSS {m['rss_rank_max_MB']:.0f} MB, of which MUMPS allocated {m['mumps_alloc_MB']:.0f} MB "
                   f"({100 * m['mumps_alloc_MB'] / m['rss_rank_max_MB']:.0f}%)")
    if len(one) >= 2:
        a, b = (one[1] if len(one) > 2 else one[0]), one[-1]     # skip the smallest: fixed costs dominate it
        dn = b["dofs"] - a["dofs"]
        slope = lambda k: math.log(b[k] / a[k]) / math.log(b["dofs"] / a["dofs"])   # noqa: E731
        out.append(f"- from {int(a['dofs'])} to {int(b['dofs'])} dofs (1 rank) the times grow like dofs^p with "
                   f"p = {slope('assembly_s'):.2f} (assembly), {slope('pcsetup_s'):.2f} (MUMPS analysis + factorisation), "
                   f"{slope('setup_s'):.2f} (set-up), {slope('total_s'):.2f} (total); memory grows by "
                   f"{1e3 * (b['rss_rank_max_MB'] - a['rss_rank_max_MB']) / dn:.1f} kB per dof "
                   f"(MUMPS: {1e3 * (b['mumps_alloc_MB'] - a['mumps_alloc_MB']) / dn:.1f} kB per dof; "
                   f"factor entries per dof {a['factor_entries'] / a['dofs']:.0f} -> {b['factor_entries'] / b['dofs']:.0f}) "
                   f"on a base of about {a['rss_rank_max_MB'] - a['dofs'] * (b['rss_rank_max_MB'] - a['rss_rank_max_MB']) / dn:.0f} MB "
                   f"per process (python, numpy, scipy, petsc4py, gmsh, MPI)")
    for m in one:
        t2 = two.get(m["elem_m"])
        if t2:
            out.append(f"- {int(m['dofs'])} dofs, 2 ranks: assembly {m['assembly_s']:.3g} -> {t2['assembly_s']:.3g} s "
                       f"(x{m['assembly_s'] / t2['assembly_s']:.2f}), set-up {m['setup_s']:.3g} -> {t2['setup_s']:.3g} s, "
                       f"MUMPS {m['pcsetup_s']:.3g} -> {t2['pcsetup_s']:.3g} s, total {m['total_s']:.3g} -> "
                       f"{t2['total_s']:.3g} s; largest rank {m['rss_rank_max_MB']:.0f} -> {t2['rss_rank_max_MB']:.0f} MB, "
                       f"all ranks {t2['rss_sum_MB']:.0f} MB")
    return out


PROBLEM_TITLE = {
    "scordelis_lo": "Scordelis-Lo roof (quarter; uz at the free-edge midspan)",
    "pinched_cylinder": "Pinched cylinder with diaphragms (octant; uz under the load)",
    "twisted_beam_in": "Twisted beam, in-plane load (mean tip displacement)",
    "twisted_beam_out": "Twisted beam, out-of-plane load (mean tip displacement)",
    "fv16": "NAFEMS FV16 cantilevered plate: 6 lowest frequencies [Hz]",
    "ss_plate": "Simply supported plate 1.5 x 1 x 0.002 m: 6 lowest frequencies [Hz] (Navier)",
}


def convergence_tables(rows):
    lines = []
    for name in dict.fromkeys(r["problem"] for r in rows):
        sel = [r for r in rows if r["problem"] == name]
        ns = sorted({int(r["n"]) for r in sel})
        modal = any(int(r["quantity"]) > 0 for r in sel)
        lines += [f"**{PROBLEM_TITLE.get(name, name)}**", ""]
        if not modal:
            ref = sel[0]["reference"]
            lines += [f"| n | mesh | free dofs | value | reference | error [%] |", "|---|---|---|---|---|---|"]
            for n in ns:
                r = [x for x in sel if int(x["n"]) == n][0]
                lines.append(f"| {n} | {r['mesh']} | {r['free_dofs']} | {_f(r['value']):.5g} | {_f(ref):.5g} | "
                             f"{100 * _f(r['rel_error']):+.3g} |")
        else:
            q = sorted({int(r["quantity"]) for r in sel})
            refs = {int(r["quantity"]): _f(r["reference"]) for r in sel}
            lines += ["| n | mesh | free dofs | " + " | ".join(f"f{k}: value (error %)" for k in q) + " |",
                      "|---|---|---|" + "---|" * len(q),
                      "| reference | | | " + " | ".join(f"{refs[k]:.5g}" for k in q) + " |"]
            for n in ns:
                rr = {int(x["quantity"]): x for x in sel if int(x["n"]) == n}
                r0 = rr[q[0]]
                lines.append(f"| {n} | {r0['mesh']} | {r0['free_dofs']} | " + " | ".join(
                    f"{_f(rr[k]['value']):.5g} ({100 * _f(rr[k]['rel_error']):+.3g})" for k in q) + " |")
        lines.append("")
    if rows:
        lines.append("![convergence.png](convergence.png)")
    return "\n".join(lines)


def replace(body, tag, text):
    b, e = f"<!-- {tag}:begin -->", f"<!-- {tag}:end -->"
    if b not in body or e not in body:
        body = body.rstrip("\n") + f"\n\n{b}\n{e}\n"
    pre, rest = body.split(b, 1)
    _, post = rest.split(e, 1)
    return pre + b + "\n" + text.rstrip("\n") + "\n" + e + post


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--logs", help="parse the benchmark logs of this directory into bench.csv/profile.csv first")
    a = ap.parse_args(argv)
    load = ""
    if a.logs:
        _, load = parse_logs(a.logs)
        parse_profile(a.logs)
    else:
        m = re.search(r"```\n(# before.*?)\n```", open(README).read() if os.path.exists(README) else "", re.S)
        load = m.group(1) if m else ""
    body = open(README).read() if os.path.exists(README) else "# Structures\n"
    bench = _read(BENCH_CSV)
    if bench:
        body = replace(body, "bench", bench_tables(bench, _read(PROFILE_CSV), load))
    conv = _read(CONV_CSV)
    if conv:
        body = replace(body, "convergence", convergence_tables(conv))
    with open(README, "w") as fh:
        fh.write(body)
    print(f"[report] tables -> {README}")


if __name__ == "__main__":
    main()
