"""The toeplitz store's kernels from a quarter of the integrals (bem/toeplitz.py ``_scatter_kernels``): an
element of the flat uniform grid is symmetric about its centre lines, so the integral of a node at the offset
(-o_x, o_y) is the mirrored node's at (o_x, o_y), each block entry (p, q) times s_p s_q (-1 per x index), and
likewise in y. The kernels built that way equal the ones integrated at every offset to round-off (H and G,
exact lags and Chebyshev's interpolating matrices, a load patch off the grid's centre, whose G window is widened
to the lattice's centred box: both sides' kernels real), with about a quarter of the kernel evaluations."""
import numpy as np
import pytest

from helpers import run_bem

pytestmark = pytest.mark.run


def test_mirror_maps():
    from petsc_ssi.bem.toeplitz import MIRROR_SLOTS, SLOTS, mirror_offsets, mirror_signs
    for f, (sx, sy) in enumerate(((1, 1), (-1, 1), (1, -1), (-1, -1))):
        for s, (dx, dy) in enumerate(SLOTS):
            assert SLOTS[MIRROR_SLOTS[f, s]] == (sx * dx, sy * dy)
    # H's entries (x,z), (y,z), (z,x), (z,y); G's (x,x), (x,y), (y,x), (y,y), (z,z)
    h = mirror_signs([0, 1, 2, 2], [2, 2, 0, 1])
    assert h.tolist() == [[1, 1, 1, 1], [-1, 1, -1, 1], [1, -1, 1, -1], [-1, -1, -1, -1]]
    g = mirror_signs([0, 0, 1, 1, 2], [0, 1, 0, 1, 2])
    assert g.tolist() == [[1] * 5, [1, -1, -1, 1, 1], [1, -1, -1, 1, 1], [1, 1, 1, 1, 1]]
    off = np.array([[3, -1, 0, 0, 0], [-3, 1, 0, 0, 0], [-3, -1, 0, 0, 0], [3, 1, 0, 0, 0], [0, -2, 0, 0, 0]])
    mirror, of, flip = mirror_offsets(off)
    assert mirror.tolist() == [[0, 2], [3, 1]]
    assert of.tolist() == [1, 1, 1, 1, 0] and flip.tolist() == [2, 1, 3, 0, 2]


def _kernels(monkeypatch, tmp_path, name, whole):
    from petsc_ssi.bem import toeplitz
    built = []
    build = toeplitz.ToeplitzHistory.build

    def keep(self, *a, **kw):
        out = build(self, *a, **kw)
        built.append(self)
        return out
    monkeypatch.setattr(toeplitz.ToeplitzHistory, "build", keep)
    if whole:                               # every offset its own mirror: each integrated where it is
        monkeypatch.setattr(toeplitz, "mirror_offsets", lambda o: (np.asarray(o)[:, :2].astype(np.int64),
                                                                   np.arange(len(o)), np.zeros(len(o), np.int64)))
    run_bem(mesh_size="8,8", mesh_h=1.0, mesh_patch="1,1", load_group="box:1.4,2.6,-0.6,0.6", load_p0=1000,
            dt=0.0025, t_end=0.05, lag_store="toeplitz", interp="chebyshev", interp_tl=0.01, interp_k=4,
            receivers="3,0,0", output_stride=0, warn_beta=0, output=tmp_path / f"{name}.h5")
    monkeypatch.undo()
    return built


def test_mirrored_kernels_equal_the_integrals_at_every_offset(monkeypatch, tmp_path):
    ref = _kernels(monkeypatch, tmp_path, "whole", True)
    got = _kernels(monkeypatch, tmp_path, "mirror", False)
    assert [t.side for t in got] == ["u", "p"]
    for a, b in zip(ref, got):
        assert a.k > 0 and a.D > 0
        for name in ("K9", "K18", "A9", "A18"):
            x, y = getattr(a, name), getattr(b, name)
            scale = np.abs(x).max()
            assert scale > 0
            assert np.abs(x - y).max() <= 1e-13 * scale, (a.side, name, np.abs(x - y).max() / scale)
        # a quarter of the offsets (and those on the axes) integrated
        assert b.nev < 0.4 * a.nev, (a.side, b.nev, a.nev)
