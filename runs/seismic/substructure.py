"""The substructure check's numbers (tests/coupling/test_substructure.py, issue 27): the difference of a
heavy rigid block's transfer function under a vertical S wave to K_h / (K_h - omega_d^2 m) from the same
mesh's impedance run, relative to its peak, at dt = 12.5 ms and at dt / 2 (whether it is the time step's).

    python runs/seismic/substructure.py        (about half a minute; prints both)
"""
import os
import sys
import tempfile
from pathlib import Path

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests"))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "coupling"))
from test_substructure import DT, transfer_error  # noqa: E402


class _Factory:
    def mktemp(self, name):
        return Path(tempfile.mkdtemp(prefix=name))


if __name__ == "__main__":
    import test_substructure
    rec = test_substructure.record.__wrapped__(_Factory())
    for dt in (DT, DT / 2):
        err, f0 = transfer_error(Path(tempfile.mkdtemp()), rec, dt)
        print(f"dt = {dt * 1e3:g} ms: max |H - K_h/(K_h - omega_d^2 m)| / max |...| = {err:.4f}; "
              f"sqrt(K_h(0)/m)/(2 pi) = {f0:.3f} Hz")
