"""Soil regions of finite elements take the soil's wave speeds (issue 42, item 4): a hex8 part given by
``cp``, ``cs`` and ``rho`` (or the box's ``-ssi_fem_cp/_cs/_rho``) is the isotropic solid of those speeds,
E = 2 rho cs^2 (1 + nu), nu = (cp^2 - 2 cs^2) / (2 (cp^2 - cs^2)); checked here against the speeds
recovered from the Lame constants, and the mixed or impossible inputs refused."""
from types import SimpleNamespace

import numpy as np
import pytest

from petsc_ssi.fem.parts import parse_parts
from petsc_ssi.petsc import SSIError

pytestmark = pytest.mark.unit


def speeds(p):
    lam = p.E * p.nu / ((1 + p.nu) * (1 - 2 * p.nu))
    mu = p.E / (2 * (1 + p.nu))
    return np.sqrt((lam + 2 * mu) / p.rho), np.sqrt(mu / p.rho)


def cfg(**kw):
    base = dict(fem_parts="", fem_E=1.0, fem_nu=0.2, fem_rho=2000.0, fem_cp=0.0, fem_cs=0.0)
    base.update(kw)
    ns = SimpleNamespace(**base)
    ns.get = lambda k, d=None: getattr(ns, k, d)
    ns.user_set = lambda k: k in kw
    return ns


@pytest.mark.parametrize("cp,cs", [(548.0, 316.0), (400.0, 150.0), (1500.0, 200.0)])
def test_a_part_by_its_wave_speeds_has_them(cp, cs):
    spec, = parse_parts(cfg(fem_parts="soil"), raw={"soil_element": "hex8", "soil_cp": str(cp),
                                                    "soil_cs": str(cs), "soil_rho": "1800"})
    assert np.allclose(speeds(spec.props), (cp, cs), rtol=1e-13)
    box, = parse_parts(cfg(fem_cp=cp, fem_cs=cs, fem_rho=1800.0), raw={})
    assert np.allclose(speeds(box.props), (cp, cs), rtol=1e-13)


@pytest.mark.parametrize("raw,msg", [
    ({"soil_element": "hex8", "soil_cp": "548", "soil_cs": "316", "soil_rho": "2000", "soil_E": "1e8"},
     "not E or nu"),
    ({"soil_element": "hex8", "soil_cp": "548", "soil_rho": "2000"}, "cp, cs and rho together"),
    ({"soil_element": "hex8", "soil_cp": "300", "soil_cs": "316", "soil_rho": "2000"}, "cp > 2 cs / sqrt(3)"),
    ({"soil_element": "shell", "soil_cp": "548", "soil_cs": "316", "soil_rho": "2000", "soil_thickness": "1"},
     "has no property 'cp'"),
])
def test_mixed_or_impossible_speeds_are_refused(raw, msg):
    with pytest.raises(SSIError, match=msg.replace("(", r"\(").replace(")", r"\)")):
        parse_parts(cfg(fem_parts="soil"), raw=raw)


def test_the_box_refuses_speeds_beside_E():
    with pytest.raises(SSIError, match="drop -ssi_fem_E"):
        parse_parts(cfg(fem_cp=548.0, fem_cs=316.0, fem_E=3e8), raw={})


def test_the_box_refuses_speeds_without_a_density():
    """-ssi_fem_cp/-ssi_fem_cs without -ssi_fem_rho: before, the region took the structure's default density
    (2000 kg/m^3) silently, so a region meant as the half-space's own soil (rho 1800) scattered (found by an
    independent check of 2026-12-03)."""
    with pytest.raises(SSIError, match="takes cp, cs and -ssi_fem_rho together"):
        parse_parts(cfg(fem_cp=548.0, fem_cs=316.0), raw={})


# ---------------------------------------------------------------- layers by depth in one part (issue 42, item 4)

COLUMN_GEO = """// a 1 m x 1 m soil column, 3 m deep: 1 m over 2 m, hex8 (extruded, recombined)
Point(1) = {-0.5, -0.5, 0}; Point(2) = {0.5, -0.5, 0}; Point(3) = {0.5, 0.5, 0}; Point(4) = {-0.5, 0.5, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Curve{1, 2, 3, 4} = 3; Transfinite Surface{1}; Recombine Surface{1};
up[] = Extrude {0, 0, -1} {Surface{1}; Layers{2}; Recombine;};
lo[] = Extrude {0, 0, -2} {Surface{up[0]}; Layers{4}; Recombine;};
Physical Volume("column") = {up[1], lo[1]};
Physical Volume("upper") = {up[1]};
Physical Volume("lower") = {lo[1]};
Physical Surface("base") = {lo[0]};
"""


def test_layers_by_depth_are_layers_by_part(tmp_path):
    """One hex8 part layered by depth (-ssi_fem_part_column_layers '-1:...;-3:...') is the same structure as
    two parts, one per layer (upper: z in [-1, 0], lower: [-3, -1]): a fixed-base run under a point load on the
    top gives the same receiver histories (1e-12 of the peak), the layers are not the same soil (the run with
    one soil differs by more than 1 %), and cells below the last layer are refused in one line."""
    import h5py
    from helpers import cli
    geo = tmp_path / "column.geo"
    geo.write_text(COLUMN_GEO)
    soft, stiff = "300,150,1700", "600,300,1900"
    common = ["-ssi_problem", "fem", "-ssi_fem_mesh", str(geo), "-ssi_fem_fixed", "base", "-ssi_fem_point_load",
              "0.5,0.5,0,1e5,0,-1e5", "-ssi_fem_load_history", "box", "-ssi_fem_load_t0", "0.01", "-ssi_dt", "0.002",
              "-ssi_t_end", "0.06", "-ssi_receivers", "0.5,0.5,0;0,0,-1", "-ssi_fem_renumber", "0"]
    runs = {}
    for name, parts in (("layers", ["-ssi_fem_parts", "column", "-ssi_fem_part_column_element", "hex8",
                                    "-ssi_fem_part_column_layers", f"-1:{soft};-3:{stiff}"]),
                        ("parts", ["-ssi_fem_parts", "upper,lower"] + [
                            a for nm, v in (("upper", soft), ("lower", stiff)) for a in (
                                f"-ssi_fem_part_{nm}_element", "hex8", f"-ssi_fem_part_{nm}_cp", v.split(",")[0],
                                f"-ssi_fem_part_{nm}_cs", v.split(",")[1], f"-ssi_fem_part_{nm}_rho", v.split(",")[2])]),
                        ("one", ["-ssi_fem_parts", "column", "-ssi_fem_part_column_element", "hex8",
                                 "-ssi_fem_part_column_layers", f"-3:{soft}"])):
        cli(common + parts + ["-ssi_output", str(tmp_path / f"{name}.h5")])
        with h5py.File(tmp_path / f"{name}.h5", "r") as f:
            runs[name] = f["receivers/u"][()]
    u = runs["parts"]
    assert np.abs(u).max() > 0
    assert np.abs(runs["layers"] - u).max() <= 1e-12 * np.abs(u).max()
    assert np.abs(runs["one"] - u).max() > 1e-2 * np.abs(u).max()
    p = cli(common + ["-ssi_fem_parts", "column", "-ssi_fem_part_column_element", "hex8",
                      "-ssi_fem_part_column_layers", f"-1:{soft};-2:{stiff}", "-ssi_output", str(tmp_path / "x.h5")],
            check=False)
    errs = [ln for ln in p.stderr.splitlines() if ln.startswith("petsc-ssi: error:")]
    assert p.returncode != 0 and len(errs) == 1 and "lie below the last layer's bottom (z = -2 m" in errs[0], p.stdout


@pytest.mark.parametrize("layers,msg", [
    ("-1:300,150,1700;-0.5:600,300,1900", "the layers' bottom elevations must fall"),
    ("-1:300,150", "layer 1's cp,cs,rho"),
    ("300,150,1700", "is not 'z:cp,cs,rho'"),
    ("-1:100,150,1700", "wave speeds cp 100, cs 150"),
    ("", "no layer"),
])
def test_bad_layers_refused(layers, msg):
    with pytest.raises(SSIError) as e:
        parse_parts(cfg(fem_parts="soil"), raw={"soil_element": "hex8", "soil_layers": layers})
    assert msg in str(e.value) and "\n" not in str(e.value), str(e.value)


def test_layers_take_no_part_material():
    with pytest.raises(SSIError) as e:
        parse_parts(cfg(fem_parts="soil"), raw={"soil_element": "hex8", "soil_layers": "-1:300,150,1700",
                                                "soil_rho": "1800"})
    assert "each layer gives its cp, cs and rho; drop -ssi_fem_part_soil_rho" in str(e.value)
    spec, = parse_parts(cfg(fem_parts="soil"), raw={"soil_element": "hex8", "soil_layers": "-1:300,150,1700;-4:600,300,1900"})
    from petsc_ssi.fem.parts import layer_of
    assert list(layer_of(spec, [0.5, -0.5, -1.0, -1.0 - 1e-6, -3.9, -4.5])) == [0, 0, 0, 1, 1, -1]
    assert np.allclose(speeds(spec.layers[1][1]), (600.0, 300.0), rtol=1e-13)


def test_a_layer_that_holds_no_cell_is_warned(tmp_path):
    """On the 3 m column (cells of 0.5 m): a layer wholly above the part's top (its bottom at +0.5 m: a sign
    slip, or a site profile reused for a buried part) and a layer thinner than the cells (-1.1 to -1.2 m:
    no centroid in it) each get one warning line naming the layer; the run goes on."""
    from helpers import cli
    geo = tmp_path / "column.geo"
    geo.write_text(COLUMN_GEO)
    a, b = "300,150,1700", "600,300,1900"
    p = cli(["-ssi_problem", "fem", "-ssi_fem_mesh", str(geo), "-ssi_fem_fixed", "base", "-ssi_fem_point_load",
             "0.5,0.5,0,1e5,0,-1e5", "-ssi_dt", "0.002", "-ssi_t_end", "0.004", "-ssi_fem_parts", "column",
             "-ssi_fem_part_column_element", "hex8", "-ssi_fem_part_column_layers",
             f"0.5:{a};-1.1:{a};-1.2:{b};-3:{b}", "-ssi_output", str(tmp_path / "w.h5")])
    warns = [ln for ln in p.stdout.splitlines() if ln.startswith("petsc-ssi: warning: part 'column'")]
    assert len(warns) == 2, p.stdout[-3000:]
    assert "layer 1's bottom z = 0.5 m is at or above the part's top (z = 0 m)" in warns[0], warns
    assert "layer 3 (bottom z = -1.2 m) holds no cell centroid" in warns[1], warns
