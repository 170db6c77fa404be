// Soil surface of the paper's building example (Romero, Galvin & Dominguez, Sec. 5.2,
// Fig. 13): nine-node quadrilaterals (Mesh.ElementOrder 2, Recombine, Transfinite) on a
// square centred on the building (plan [-a, a] x [-b, b], a = 7.2, b = 5.4 m), extended in
// +x when needed to cover the load patch, and a w x w load patch centred at (xl, 0).
//
// Layout: a tensor grid of straight-sided cells (every cell its own 1 x 1 Transfinite +
// Recombine surface, so every node position is set here and the full model is the exact
// mirror of the half model).
//   x lines: [xmin, -a] graded outwards from h (growth g, cells at most hm);
//            [-a, a] uniform, size h (the slab: 2a/h cells);
//            [a, xl - w/2] uniform, about hr (between building and load);
//            [xl - w/2, xl + w/2] the patch (one cell);
//            [xl + w/2, xmax] uniform, about hq;  xmax = max(Lx/2, xl + w/2 + mr).
//   y lines: under the building uniform, size hy (default h); through the load patch the
//            same number of lines but with the patch edges +-w/2 (and y = 0) as lines; the
//            columns between the building and the patch interpolate linearly in x;
//            [b, Ly/2] graded outwards like the left part.
// With h = 1.2 m the nodes under the slab (spacing h/2 = 0.6 m, midside nodes included) are
// the foundation slab's 0.6 m shell nodes (meshes/building.geo): -ssi_interface auto.
// Half model (ymin = 0, given by petsc-ssi with -ssi_symmetry y=sym): needs y = 0 to be a
// cell edge under the slab, i.e. b/hy an integer (an even number of cells across the slab).
// The paper's building (3 bays of 3.6 m in y, 0.6 m shells) has 9 cells of 1.2 m across
// 10.8 m: no half model is possible with it (see runs/building/README.md); with 4 bays of
// 2.7 m in y the slab nodes are 0.54 m apart in y: hy = 1.08 (10 cells, 5 per half).
//
// Physical surfaces: "soil" (all), "load" (the patch: -ssi_load_group load), "slab" (the
// cells under the building), "free" (the others).
// Parameters (ONELAB "Parameters/..."; petsc-ssi sets Lx, Ly, xmin, ymin from -ssi_mesh_size
// and -ssi_symmetry, h from -ssi_mesh_h, a, b from -ssi_mesh_patch; the others with
// -ssi_mesh_params name=value,...):
//   hy   cell size in y under the slab (0: = h)
//   xl   x of the load centre (14.5: 14.5 m from the building's centre; 21.7: from its edge)
//   w    side of the square load patch (1)
//   hr   target cell size between the building and the patch (1.4)
//   hq   target cell size beyond the patch (1.5)
//   mr   soil margin beyond the patch when the square is extended (3)
//   g, hm  growth factor and largest cell of the graded far field (1.3, 3.0)
DefineConstant[ Lx = {36, Name "Parameters/Lx"}, Ly = {36, Name "Parameters/Ly"},
                xmin = {-18, Name "Parameters/xmin"}, ymin = {-18, Name "Parameters/ymin"},
                h = {1.2, Name "Parameters/h"}, a = {7.2, Name "Parameters/a"},
                b = {5.4, Name "Parameters/b"}, hy = {0, Name "Parameters/hy"},
                xl = {14.5, Name "Parameters/xl"}, w = {1.0, Name "Parameters/w"},
                hr = {1.4, Name "Parameters/hr"}, hq = {1.5, Name "Parameters/hq"},
                mr = {3.0, Name "Parameters/mr"}, g = {1.3, Name "Parameters/g"},
                hm = {3.0, Name "Parameters/hm"} ];
If (hy <= 0)
  hy = h;
EndIf
half = (ymin > -1e-9);
tol = 1e-6;
nbx = Round(2 * a / h);
nby = Round(2 * b / hy);
If (Fabs(nbx * h - 2 * a) > tol || Fabs(nby * hy - 2 * b) > tol)
  Error("building_soil.geo: 2a/h = %g and 2b/hy = %g must be integers", 2 * a / h, 2 * b / hy);
EndIf
If (half == 1 && nby % 2 == 1)
  Error("building_soil.geo: a half model (y >= 0) needs y = 0 to be a cell edge under the slab, i.e. an even number 2b/hy (here %g): set hy (and a building whose slab nodes match)", nby);
EndIf
x0p = xl - w / 2; x1p = xl + w / 2;
If (x0p < a + 0.5 * h)
  Error("building_soil.geo: the load patch (x from %g) must lie beyond the building (x = %g)", x0p, a);
EndIf
xmax = Max(Lx / 2, x1p + mr);
ytop = Ly / 2;

// graded cell sizes: from the size gs0 next to the inner edge, growing by g, at most hm,
// their number the one whose sum is closest to gL, then scaled to gL exactly -> gsz[]
Macro Graded
  gsz[] = {}; gsum = 0; gs = gs0; gdone = 0;
  For gk In {0:400}
    If (gdone == 0)
      gs = Min(gs * g, hm);
      If (gsum + gs >= gL)
        If (gsum + gs - gL > gL - gsum && #gsz[] > 0)
          gdone = 1;
        Else
          gsz[] += {gs}; gsum += gs; gdone = 1;
        EndIf
      Else
        gsz[] += {gs}; gsum += gs;
      EndIf
    EndIf
  EndFor
  For gk In {0:#gsz[]-1}
    gsz[gk] = gsz[gk] * gL / gsum;
  EndFor
Return

// ---- x lines
xs[] = {};
gs0 = h; gL = -a - xmin; Call Graded;            // left far field, from the building outwards
nl = #gsz[];
xx = xmin;
For k In {0:nl-1}
  xs[] += {xx}; xx += gsz[nl - 1 - k];
EndFor
For i In {0:nbx-1}
  xs[] += {-a + i * h};
EndFor
i_bR = #xs[];                                   // index of x = a
n1 = Max(1, Round((x0p - a) / hr));
For i In {0:n1-1}
  xs[] += {a + i * (x0p - a) / n1};
EndFor
i_p0 = #xs[];                                   // index of x = xl - w/2
xs[] += {x0p};
n3 = Max(1, Round((xmax - x1p) / hq));
For i In {0:n3}
  xs[] += {x1p + i * (xmax - x1p) / n3};
EndFor
NX = #xs[];
xs[i_bR] = a;

// ---- y lines: building distribution yb[], patch distribution yp[] (same count), outer part
yb[] = {}; yp[] = {};
// inner lines with y >= 0 (building): 0 (if a line) then up to b
ib[] = {};
If (nby % 2 == 0)
  For j In {0:nby/2}
    ib[] += {j * hy};
  EndFor
Else
  For j In {0:(nby-1)/2}
    ib[] += {hy / 2 + j * hy};
  EndFor
EndIf
// patch: the first line at or above 0 that is not 0 is w/2, the rest uniform up to b
ip[] = {};
For j In {0:#ib[]-1}
  If (Fabs(ib[j]) < tol)
    ip[] += {0.0};
  EndIf
EndFor
nz = #ip[];                                      // 1 if y = 0 is a line
m = #ib[] - nz;                                  // lines above 0
If (m < 2)
  Error("building_soil.geo: too few cells across the slab for the load patch rows");
EndIf
If (w / 2 >= b)
  Error("building_soil.geo: the load patch must be narrower than the building");
EndIf
For j In {0:m-1}
  ip[] += {w / 2 + j * (b - w / 2) / (m - 1)};
EndFor
// outer lines above b
gs0 = hy; gL = ytop - b; Call Graded;
yo[] = {};
yy = b;
For k In {0:#gsz[]-1}
  yy += gsz[k]; yo[] += {yy};
EndFor
yo[#yo[]-1] = ytop;
// assemble: [mirror (full model)] inner outer
If (half == 0)
  For k In {0:#yo[]-1}
    yb[] += {-yo[#yo[]-1-k]}; yp[] += {-yo[#yo[]-1-k]};
  EndFor
  For j In {0:#ib[]-1}
    If (Fabs(ib[#ib[]-1-j]) > tol)
      yb[] += {-ib[#ib[]-1-j]}; yp[] += {-ip[#ip[]-1-j]};
    EndIf
  EndFor
EndIf
For j In {0:#ib[]-1}
  yb[] += {ib[j]}; yp[] += {ip[j]};
EndFor
For k In {0:#yo[]-1}
  yb[] += {yo[k]}; yp[] += {yo[k]};
EndFor
NY = #yb[];

// ---- points (column i: yb below x = a, yp from the patch on, linear in x between)
pt[] = {};
For i In {0:NX-1}
  f = 0;
  If (xs[i] > a + tol)
    f = Min(1, (xs[i] - a) / (x0p - a));
  EndIf
  For j In {0:NY-1}
    p = newp; Point(p) = {xs[i], yb[j] + f * (yp[j] - yb[j]), 0}; pt[] += {p};
  EndFor
EndFor
// lines along y: ly[i * (NY - 1) + j]; along x: lx[j * (NX - 1) + i]
ly[] = {};
For i In {0:NX-1}
  For j In {0:NY-2}
    l = newl; Line(l) = {pt[i * NY + j], pt[i * NY + j + 1]}; ly[] += {l};
  EndFor
EndFor
lx[] = {};
For j In {0:NY-1}
  For i In {0:NX-2}
    l = newl; Line(l) = {pt[i * NY + j], pt[(i + 1) * NY + j]}; lx[] += {l};
  EndFor
EndFor
Transfinite Curve{ly[], lx[]} = 2;
sl[] = {}; ld[] = {}; fr[] = {}; all[] = {};
For i In {0:NX-2}
  For j In {0:NY-2}
    c = newcl;
    Curve Loop(c) = {lx[j * (NX - 1) + i], ly[(i + 1) * (NY - 1) + j], -lx[(j + 1) * (NX - 1) + i],
                     -ly[i * (NY - 1) + j]};
    s = news; Plane Surface(s) = {c};
    Transfinite Surface{s}; Recombine Surface{s};
    all[] += {s};
    xc = 0.5 * (xs[i] + xs[i + 1]); yc = 0.5 * (yb[j] + yb[j + 1]);
    If (xs[i] > -a - tol && xs[i + 1] < a + tol && Fabs(yb[j]) < b + tol && Fabs(yb[j + 1]) < b + tol)
      sl[] += {s};
    ElseIf (i == i_p0 && Fabs(yp[j]) < w / 2 + tol && Fabs(yp[j + 1]) < w / 2 + tol)
      ld[] += {s};
    Else
      fr[] += {s};
    EndIf
  EndFor
EndFor
Physical Surface("soil") = {all[]};
Physical Surface("slab") = {sl[]};
Physical Surface("load") = {ld[]};
Physical Surface("free") = {fr[]};
Mesh.ElementOrder = 2;
Mesh.SecondOrderIncomplete = 0;
