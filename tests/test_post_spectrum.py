"""petsc-ssi post --spectrum / --transfer (petsc_ssi.spectrum): synthetic series with known
answers written with h5py, and one real structure run (slab on columns) against its modes."""
import io
import os
import subprocess
import sys

import numpy as np
import pytest

from helpers import ROOT, PY, cli

from petsc_ssi import spectrum as sp
from petsc_ssi.app.post import main as post_main

pytestmark = pytest.mark.run

# two sines with an integer number of periods in T = N dt = 2 s: 5 Hz (10 periods) and 12.5 Hz (25)
N, DT = 200, 0.01
F1, A1, F2, A2 = 5.0, 1.5, 12.5, 0.4


def _t(n=N, dt=DT):
    return np.arange(n) * dt


def _two_sines(t):
    return A1 * np.sin(2 * np.pi * F1 * t) + A2 * np.sin(2 * np.pi * F2 * t + 0.3)


def _write(path, t, u, interface=None, points=None):
    """An output file like a run's: receivers/t (K,), receivers/u (K, R, 3), receivers/points."""
    import h5py
    with h5py.File(path, "w") as f:
        g = f.create_group("receivers")
        g["t"] = t
        g["u"] = u
        g["points"] = points if points is not None else np.zeros((u.shape[1], 3))
        if interface is not None:
            gi = f.create_group("interface")
            for k, v in interface.items():
                gi[k] = v
    return path


def _read_csv(path):
    header, rows, names = [], [], None
    for ln in open(path):
        if ln.startswith("#"):
            header.append(ln[1:].strip())
        elif names is None:
            names = ln.strip().split(",")
        else:
            rows.append([float(v) for v in ln.split(",")])
    return header, names, np.array(rows)


def _run(argv):
    """post main in-process: (status, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    old = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = out, err
    try:
        rc = post_main(argv)
    finally:
        sys.stdout, sys.stderr = old
    return rc, out.getvalue(), err.getvalue()


def _printed_peaks(stdout):
    """{component: [(f, a), ...]} from the peak table printed by --spectrum."""
    res = {}
    for ln in stdout.splitlines():
        if ln.startswith("#") or ln.startswith("component,"):
            continue
        c, _, f, a = ln.split(",")
        res.setdefault(c, []).append((float(f), float(a)))
    return res


@pytest.fixture
def sines(tmp_path):
    t = _t()
    u = np.zeros((N, 2, 3))
    u[:, 0, 0] = _two_sines(t)
    u[:, 0, 2] = 0.7 * np.cos(2 * np.pi * 20.0 * t)
    u[:, 1] = 2.0 * u[:, 0]
    return _write(str(tmp_path / "sines.h5"), t, u)


# ------------------------------------------------------------------ library

def test_sine_amplitude_scaling_and_windows():
    t = _t()
    x = _two_sines(t)
    f, a, info = sp.amplitude_spectrum(t, x)
    assert info["nfft"] == N and info["df"] == pytest.approx(1 / (N * DT))
    for fk, ak in ((F1, A1), (F2, A2)):
        k = int(round(fk / info["df"]))
        assert a[k] == pytest.approx(ak, rel=1e-9)
    # a constant gives its value at f = 0 (DC not doubled)
    assert sp.amplitude_spectrum(t, np.full(N, 3.0))[1][0] == pytest.approx(3.0)
    # windows divide out their coherent gain: an on-bin sine still reads its amplitude
    for w in ("hann", "tukey"):
        f, a, info = sp.amplitude_spectrum(t, x, window=w)
        fp, ap, _ = sp.peaks(f, a, 2, min_separation=2 * info["resolution"])
        assert sorted(fp) == pytest.approx([F1, F2])
        assert sorted(ap) == pytest.approx([A2, A1], rel=0.02), w
    # padding: next power of two >= pad * N
    assert sp.amplitude_spectrum(t, x, pad=1)[2]["nfft"] == 256
    assert sp.amplitude_spectrum(t, x, pad=4)[2]["nfft"] == 1024
    assert sp.amplitude_spectrum(t, x, pad=5.12)[2]["nfft"] == 1024
    assert sp.amplitude_spectrum(t, x, pad=5.13)[2]["nfft"] == 2048


def test_peaks_min_separation_and_edges():
    f = np.arange(10.0)
    a = np.array([9, 1, 5, 1, 4.9, 1, 3, 1, 1, 8.0])  # ends are never peaks
    fp, ap, idx = sp.peaks(f, a, 3)
    assert list(fp) == [2, 4, 6]
    fp, _, _ = sp.peaks(f, a, 3, min_separation=2.5)
    assert list(fp) == [2, 6]


def test_nonuniform_grid_is_an_error():
    t = _t()
    t[50] += 0.3 * DT
    with pytest.raises(sp.SpectrumError, match="not uniform"):
        sp.amplitude_spectrum(t, np.sin(t))


# ------------------------------------------------------------------ command line

def test_cli_spectrum_two_sines_peaks_csv_png(sines, tmp_path):
    csv, png = str(tmp_path / "s.csv"), str(tmp_path / "s.png")
    rc, out, err = _run([sines, "--spectrum", "--component", "x", "--peaks", "2", "--csv", csv, "--png", png])
    assert rc == 0, err
    pk = _printed_peaks(out)["u_x"]
    df = 1 / (N * DT)
    assert len(pk) == 2
    (fa, aa), (fb, ab) = pk
    assert abs(fa - F1) <= df and abs(fb - F2) <= df
    assert aa == pytest.approx(A1, rel=0.01) and ab == pytest.approx(A2, rel=0.01)
    header, names, data = _read_csv(csv)
    text = "\n".join(header)
    assert names == ["f_hz", "u_x"]
    assert os.path.abspath(sines) in text and "receivers/u receiver 0" in text
    assert "window: none" in text and "no zero padding" in text and f"df: {df:.9g} Hz" in text
    assert np.allclose(np.diff(data[:, 0]), df)
    k = int(np.argmax(data[:, 1]))
    assert data[k, 0] == pytest.approx(F1) and data[k, 1] == pytest.approx(A1, rel=0.01)
    with open(png, "rb") as fh:
        assert fh.read(8) == b"\x89PNG\r\n\x1a\n"
    import matplotlib.image
    img = matplotlib.image.imread(png)
    assert img.shape[0] > 300 and img.shape[1] > 600 and img[..., :3].std() > 0.01


def test_cli_padding_refines_df_as_stated(sines, tmp_path):
    csv = str(tmp_path / "p.csv")
    rc, out, err = _run([sines, "--spectrum", "--component", "x", "--pad", "4", "--peaks", "2", "--csv", csv])
    assert rc == 0, err
    header, names, data = _read_csv(csv)
    nfft = 1024  # next power of two >= 4 * 200
    df = 1 / (nfft * DT)
    text = "\n".join(header)
    assert f"to nfft = {nfft}" in text and f"df: {df:.9g} Hz" in text
    assert np.allclose(np.diff(data[:, 0]), df) and data.shape[0] == nfft // 2 + 1
    (fa, aa), (fb, ab) = _printed_peaks(out)["u_x"]
    assert abs(fa - F1) <= df and abs(fb - F2) <= df
    # the padded spectrum interpolates the unpadded one: equal values at the shared frequencies
    f0, a0, _ = sp.amplitude_spectrum(_t(), _two_sines(_t()))
    on = np.isclose((data[:, 0] / (1 / (N * DT))) % 1, 0, atol=1e-9) | \
        np.isclose((data[:, 0] / (1 / (N * DT))) % 1, 1, atol=1e-9)
    common = np.round(data[on, 0] * N * DT).astype(int)
    assert np.allclose(data[on, 1], a0[common], atol=1e-12)


def test_cli_nonuniform_grid_exit_2_one_line(tmp_path):
    t = _t()
    t[77] += 0.2 * DT
    u = np.zeros((N, 1, 3))
    u[:, 0, 0] = _two_sines(_t())
    path = _write(str(tmp_path / "bad.h5"), t, u)
    p = subprocess.run([PY, "-m", "petsc_ssi", "post", path, "--spectrum"], cwd=ROOT,
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 2
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("petsc-ssi post: error:") and "not uniform" in lines[0], p.stderr
    # a missing series is the same kind of error
    rc, _, err = _run([path, "--spectrum", "--series", "interface/force_be"])
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "interface/force_be" in err


def test_cli_transfer_b_is_2a(sines, tmp_path):
    csv = str(tmp_path / "h.csv")
    rc, out, err = _run([sines, "--transfer", "0", "1", "--csv", csv, "--png", str(tmp_path / "h.png")])
    assert rc == 0, err
    header, names, data = _read_csv(csv)
    assert "regularised" in "\n".join(header)
    assert names[:4] == ["f_hz", "mag_x", "phase_deg_x", "reliable_x"]
    for c in ("x", "z"):
        mag = data[:, names.index(f"mag_{c}")]
        ph = data[:, names.index(f"phase_deg_{c}")]
        rel = data[:, names.index(f"reliable_{c}")] > 0
        assert rel.sum() >= 1
        # the water level biases |H| by at most (eps / 0.05)^2 = 4e-4 where |A| >= 5% max|A|
        assert np.allclose(mag[rel], 2.0, rtol=4e-4) and np.allclose(ph[rel], 0.0, atol=1e-6)
        assert abs(mag[np.argmax(mag)] - 2.0) < 1e-5
    # y is identically zero: nothing reliable, and H -> 0 rather than 0/0
    assert not (data[:, names.index("reliable_y")] > 0).any()
    assert np.all(np.isfinite(data)) and np.all(data[:, names.index("mag_y")] == 0)
    assert os.path.getsize(str(tmp_path / "h.png")) > 1000

    # B from another file with the same grid (FILE2.h5:K), and a different grid is refused
    t = _t()
    u2 = np.zeros((N, 1, 3))
    u2[:, 0] = 2.0 * _two_sines(t)[:, None]
    other = _write(str(tmp_path / "other.h5"), t, u2)
    rc, out, err = _run([sines, "--transfer", "0", f"{other}:0", "--component", "x", "--csv", csv, "--overwrite"])
    assert rc == 0, err
    _, names, data = _read_csv(csv)
    rel = data[:, 3] > 0
    assert np.allclose(data[rel, 1], 2.0, rtol=4e-4) and np.allclose(data[rel, 2], 0.0, atol=1e-6)
    short = _write(str(tmp_path / "short.h5"), t[:150], u2[:150])
    rc, _, err = _run([sines, "--transfer", "0", f"{short}:0"])
    assert rc == 2 and "different time grids" in err and len(err.strip().splitlines()) == 1


def test_cli_interface_force_series(tmp_path):
    t = _t()
    fbe = np.zeros((N, 3))
    fbe[:, 2] = 1e4 * np.sin(2 * np.pi * 7.5 * t)  # 15 periods in 2 s
    path = _write(str(tmp_path / "ssi.h5"), t, np.zeros((N, 1, 3)),
                  interface={"t": t, "force_be": fbe, "force_fe": 0.5 * fbe})
    csv = str(tmp_path / "i.csv")
    rc, out, err = _run([path, "--spectrum", "--series", "interface/force_be", "--component", "z",
                         "--peaks", "1", "--csv", csv])
    assert rc == 0, err
    (f, a), = _printed_peaks(out)["force_be_z"]
    assert f == pytest.approx(7.5) and a == pytest.approx(1e4, rel=1e-6)
    rc, out, err = _run([path, "--transfer", "interface/force_be", "interface/force_fe", "--component", "z",
                         "--csv", csv, "--overwrite"])
    assert rc == 0, err
    _, names, data = _read_csv(csv)
    rel = data[:, 3] > 0
    assert np.allclose(data[rel, 1], 0.5, rtol=4e-4)


# ------------------------------------------------------------------ a real structure run

@pytest.fixture(scope="module")
def slab(tmp_path_factory):
    d = tmp_path_factory.mktemp("slab")
    opts = "runs/structures/slab-on-columns.opts"
    run, modes = str(d / "slab.h5"), str(d / "m.h5")
    cli(["-options_file", opts, "-ssi_output", run, "-ssi_t_end", "0.2"], timeout=300)
    cli(["modes", "-options_file", opts, "-ssi_modes_n", "3", "-ssi_output", modes], timeout=300)
    import h5py
    with h5py.File(modes, "r") as f:
        freqs = np.asarray(f.attrs["frequencies_hz"], dtype=float)
    return run, freqs


def test_slab_spectrum_peak_at_first_natural_frequency(slab, tmp_path):
    run, freqs = slab
    f1 = freqs[0]
    assert 3.0 < f1 < 20.0
    csv = str(tmp_path / "slab.csv")
    rc, out, err = _run([run, "--spectrum", "--receiver", "0", "--component", "x", "--pad", "8", "--peaks", "1",
                         "--csv", csv, "--png", str(tmp_path / "slab.png")])
    assert rc == 0, err
    (fp, ap), = _printed_peaks(out)["u_x"]
    header, _, data = _read_csv(csv)
    res = float(next(h for h in header if h.startswith("df:")).split("resolution 1/(N dt):")[1].split()[0])
    assert res == pytest.approx(1 / 0.202, rel=1e-6)  # 101 samples of 2 ms
    # the record holds ~1.5 periods: the peak is within the true resolution 1/(N dt) of f1
    assert abs(fp - f1) <= res, (fp, f1, res)
    assert ap > 0.5 * np.abs(data[:, 1]).max()
    # a Hann window narrows the leakage bias from the record's ends
    rc, out, err = _run([run, "--spectrum", "--receiver", "0", "--component", "x", "--pad", "8",
                         "--window", "hann", "--peaks", "1"])
    (fh, _), = _printed_peaks(out)["u_x"]
    assert abs(fh - f1) <= 0.5 * res, (fh, f1)
    # the velocity of the same receiver peaks there too (structure outputs hold it)
    rc, out, err = _run([run, "--spectrum", "--quantity", "velocity", "--component", "x", "--pad", "8",
                         "--peaks", "1"])
    (fv, _), = _printed_peaks(out)["velocity_x"]
    assert rc == 0 and abs(fv - f1) <= res


def test_cli_spectrum_of_a_runs_resultants(tmp_path):
    """post --spectrum reads the resultants group of a rigid-motion run (issue 12, item 3): the
    f = 0 amplitude of the vertical force is its mean (no window, no detrend), and the header
    states the window and the padding."""
    import h5py
    from helpers import run_bem
    out = str(tmp_path / "r.h5")
    run_bem(mesh_size="2,2", mesh_h=0.5, mesh_patch="0.5,0.5", disp_group="load", disp_value="0,0,1e-6",
            disp_history="smoothstep", disp_t0=0.05, dt=0.0125, t_end=0.25, cp=42.0, cs=20.0, rho=1800.0,
            output=out, output_stride=0, warn_beta=0, monitor=0)
    csv_out = str(tmp_path / "f.csv")
    cli(["post", out, "--spectrum", "--series", "resultants/force", "--component", "z", "--pad", "2",
         "--csv", csv_out])
    text = open(csv_out).read()
    assert "# window: none" in text and "# padding: zero-padded" in text and "resultants/force" in text
    rows = np.loadtxt(csv_out, delimiter=",", comments="#", skiprows=0, dtype=str)
    data = np.array([[float(v) for v in r] for r in rows if r[0] != "f_hz"])
    with h5py.File(out, "r") as f:
        fz = f["resultants/force"][:, 2]
    nfft = 64                                          # 20 samples, padded to the power of two >= 40
    assert data[0, 1] == pytest.approx(fz.sum() / len(fz), rel=1e-6)
    assert data[1, 0] == pytest.approx(1.0 / (nfft * 0.0125), rel=1e-9)


def test_outputs_never_replace_an_input_or_a_result(sines, tmp_path):
    """Issue 30: an output path (--csv of --spectrum/--transfer, --png, --plot) naming the input,
    a sidecar of it or another HDF5 result is refused in one line (exit 2) even with --overwrite,
    before anything is read or written; an existing CSV/PNG is refused without --overwrite (as a
    run's -ssi_output without -ssi_output_overwrite) and replaced with it."""
    other = _write(str(tmp_path / "other.h5"), _t(), np.zeros((N, 1, 3)))
    side = str(tmp_path / "sines.json")
    with open(side, "w") as fh:
        fh.write("{}\n")
    old = str(tmp_path / "old.csv")
    with open(old, "w") as fh:
        fh.write("keep\n")
    keep = {p: open(p, "rb").read() for p in (sines, other, side, old)}
    cases = [
        (["--spectrum", "--csv", sines], "--csv", "is the input file"),
        (["--spectrum", "--csv", sines, "--overwrite"], "--csv", "is the input file"),
        (["--spectrum", "--png", sines], "--png", "is the input file"),
        (["--plot", sines], "--plot", "is the input file"),
        (["--transfer", "0", f"{other}:0", "--csv", other, "--overwrite"], "--csv", "is the input file"),
        (["--spectrum", "--csv", side, "--overwrite"], "--csv", "a sidecar of the input file"),
        (["--spectrum", "--png", other, "--overwrite"], "--png", "existing HDF5 file"),
        (["--spectrum", "--csv", old], "--csv", "exists (give --overwrite"),
        (["--spectrum", "--csv", str(tmp_path / "s.csv"), "--png", str(tmp_path / "s.csv")], "--png",
         "the same file as --csv"),
    ]
    for extra, opt, words in cases:
        rc, out, err = _run([sines] + extra)
        lines = err.strip().splitlines()
        assert rc == 2 and len(lines) == 1, (extra, err)
        assert lines[0].startswith(f"petsc-ssi post: error: {opt} ") and words in lines[0], (extra, lines[0])
        assert out == "" and "Traceback" not in err
        assert {p: open(p, "rb").read() for p in keep} == keep, extra
    assert not os.path.exists(tmp_path / "s.csv")
    # the command line as the tester gave it (a subprocess: no traceback, the input intact)
    p = subprocess.run([PY, "-m", "petsc_ssi", "post", sines, "--spectrum", "--csv", sines], cwd=ROOT,
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and "is the input file" in p.stderr and "Traceback" not in p.stderr, p.stderr
    assert open(sines, "rb").read() == keep[sines]
    rc, _, err = _run([sines, "--spectrum", "--component", "x", "--csv", old, "--overwrite"])
    assert rc == 0, err
    assert _read_csv(old)[1] == ["f_hz", "u_x"]
