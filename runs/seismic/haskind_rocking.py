#!/usr/bin/env python3
"""Why Haskind's reciprocity holds the rocking moments only to about 40 % (issue 46, the rocking
terms): the blocked footing's force F (total motion 0 under the wave) against H = minus the
impedance tractions of unit rigid steps convolved with the free field (tests/bem/test_haskind.py,
whose docstring derives the discrete identity), with F - H split into

    coupling: - sum_j (K_kj - K_jk) * q_j   (the asymmetry of the impedance matrix's rigid-mode block,
              K_kj^i = rho_k^T M Z_i rho_j from the same impedance runs, q_j the free field's rigid
              part on the footing: its mean translation and rotations, M-orthogonal projection)
    rest:     F - H less that (the asymmetry acting on the free field's deformation over the footing)

and, for each resultant, the shares of its own motion (the direct term K_kk q_k) and of the other
modes (K_kj q_j: for a rocking moment, the coupling to the horizontal translation) in F. Cases of
the test: SH at 60 degrees (y=anti) and P at 30 degrees (y=sym), 1 m square footing in the middle
of an L x L meshed surface, c_s 20 m/s, T = 0.1 s pulse, dt = 0.012 h; L and h vary.

    .venv/bin/python runs/seismic/haskind_rocking.py [--fine]

(about 5 minutes on 2 loaded cores; --fine adds L = 2 m with 0.125 m elements: 3 GB, 100 s). Prints
the table of runs/seismic/README.md (the Haskind section).
"""
import argparse
import os
import pathlib
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "tests"))
sys.path.insert(0, os.path.join(ROOT, "tests", "bem"))
from test_haskind import haskind_parts  # noqa: E402

NAMES = {0: "F_x", 1: "F_y", 2: "F_z", 3: "M_x", 4: "M_y", 5: "M_z"}


SH = [(2.0, 0.5), (2.0, 0.25), (3.0, 0.5), (4.0, 0.5), (6.0, 0.5), (4.0, 0.25)]     # (L, h) [m]
P = [(2.0, 0.5), (4.0, 0.5), (6.0, 0.5)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--fine", action="store_true", help="add L = 2 m, h = 0.125 m (3 GB)")
    a = ap.parse_args()
    cases = [("sh", 60, "y=anti", (1, 3, 5), L, h) for L, h in SH + ([(2.0, 0.125)] if a.fine else [])] + \
            [("p", 30, "y=sym", (0, 2, 4), L, h) for L, h in P]
    print("| wave | L [m] | h [m] | resultant | max abs(F) | max abs(H) | max abs(F - H) / max abs(F) | "
          "coupling asymmetry part | rest | direct share in F | other modes' share in F |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for wave, angle, sym, modes, L, h in cases:
        with tempfile.TemporaryDirectory() as tmp:
            parts = haskind_parts(pathlib.Path(tmp), wave, angle, sym, modes, h, 0.012 * h, L=L)
        for k in modes:
            p = parts[k]
            print(f"| {wave.upper()} {angle} deg | {L:g} | {h:g} | {NAMES[k]} | {p['F']:.4g} | {p['H']:.4g} | "
                  f"{p['total']:.4f} | {p['coupling']:.4f} | {p['rest']:.4f} | {p['direct']:.3f} | {p['cross']:.3f} |",
                  flush=True)


if __name__ == "__main__":
    main()
