// The three-storey building of Romero, Galvin & Dominguez, Sec. 5.2 (Figs. 12-14):
// 14.4 m x 10.8 m in plan, three storeys of 3 m, concrete columns (frames) on a grid of
// 3.6 m bays, beams (frames) along every column line at levels 1..ns, floor slabs and a
// foundation slab (level 0, z = 0) of four-node shells. z is up; the plan is centred at
// x = y = 0 (x: the long side, the direction of wave propagation x1 of the paper).
//
// Built-in kernel, points and curves shared: the beams ARE the slab edges on the column
// lines, the columns end at slab points, so slab, beam and column nodes coincide (one node
// each: monolithic joints, no Coherence needed). Every bay of every level is one Transfinite
// + Recombine surface: structured quads of size ~h. The lines x = 0 and y = 0 are always
// slab grid lines (when they are not column lines, they are mid-bay cut lines carrying no
// beam), so the half model (half = 1: y >= 0 only) has exactly the nodes of the full model on
// y >= 0, and the roof centre A and the foundation centre B are geometric points.
//
// Physical groups
//   foundation  surface: the slab at z = 0 (shell part; fix it for a fixed base)
//   floors      surface: the slabs of levels 1 .. ns-1
//   roof        surface: the slab of level ns
//   columns     curve: the columns (frames), nz elements of size ~hc per storey
//   ext_beams   curve: beams on the perimeter column lines, levels 1..ns
//   int_beams   curve: beams on the interior column lines, levels 1..ns
//   base        surface: the foundation slab again (every node of it is on the soil)
//   A           point: the roof centre (0, 0, H)
//   B           point: the foundation centre (0, 0, 0), below A
//   sym_y       curve: every slab grid line on y = 0 (all levels), plus the columns on y = 0
//               when y = 0 is a column line (ny even): the nodes of the symmetry plane
//   int_beams_sym, columns_sym  (half = 1 and y = 0 a column line only) the beams and
//               columns lying in the symmetry plane: they carry half their section and
//               added mass in a half model (b/2: A and Iy halve exactly; Iz and J act only
//               through uy, rx, rz, which the symmetry fixes)
//
// Parameters (ONELAB "Parameters/..."; gmsh -setnumber NAME VALUE, or
// gmsh.onelab.setNumber("Parameters/NAME", [v]) before gmsh.open):
//   nbx, nby   bays in x and y (default 4 x 3: a 5 x 4 grid of columns)
//   sx, sy     bay spacing in x and y [m] (3.6)
//   ns, hs     storeys and storey height [m] (3, 3)
//   h          slab (and beam) element size [m] (0.6)
//   hc         column element size [m] (0.3)
//   half       0: full building; 1: the half y >= 0 (symmetry about y = 0)
DefineConstant[
  nbx = {4, Min 1, Max 1000, Step 1, Name "Parameters/nbx"}, nby = {3, Min 1, Max 1000, Step 1, Name "Parameters/nby"},
  sx = {3.6, Min 0.001, Name "Parameters/sx"}, sy = {3.6, Min 0.001, Name "Parameters/sy"},
  ns = {3, Min 1, Max 1000, Step 1, Name "Parameters/ns"}, hs = {3.0, Min 0.001, Name "Parameters/hs"},
  h = {0.6, Min 0.001, Name "Parameters/h"}, hc = {0.3, Min 0.001, Name "Parameters/hc"},
  half = {0, Name "Parameters/half", Choices {0, 1}} ];
// (Min, Step, Choices: the values petsc-ssi accepts in -ssi_fem_mesh_params; gmsh itself does not check)

Lx = nbx * sx; Ly = nby * sy; tol = 1e-6 * (sx + sy);

// grid lines in x: the column lines, and x = 0 between them when nbx is odd
xs[] = {}; cx[] = {};
For i In {0:nbx}
  xs[] += {-Lx / 2 + i * sx}; cx[] += {1};
  If (nbx % 2 == 1 && i == (nbx - 1) / 2)
    xs[] += {0.0}; cx[] += {0};
  EndIf
EndFor
// grid lines in y: the same, and with half = 1 only those with y >= 0
ys[] = {}; cy[] = {};
For j In {0:nby}
  y = -Ly / 2 + j * sy;
  If (half == 0 || y > -tol)
    ys[] += {y}; cy[] += {1};
  EndIf
  If (nby % 2 == 1 && j == (nby - 1) / 2)
    ys[] += {0.0}; cy[] += {0};
  EndIf
EndFor
NX = #xs[]; NY = #ys[];

// points P[k][j][i] -> pt[(k * NY + j) * NX + i]
pt[] = {};
For k In {0:ns}
  For j In {0:NY-1}
    For i In {0:NX-1}
      p = newp; Point(p) = {xs[i], ys[j], k * hs}; pt[] += {p};
    EndFor
  EndFor
EndFor

ext[] = {}; inb[] = {}; intsym[] = {}; symc[] = {}; colsym[] = {}; cols[] = {};
fnd[] = {}; flo[] = {}; rof[] = {};

// lines along x: lx[(k * NY + j) * (NX - 1) + i] from (i, j) to (i + 1, j)
lx[] = {};
For k In {0:ns}
  For j In {0:NY-1}
    For i In {0:NX-2}
      l = newl; Line(l) = {pt[(k * NY + j) * NX + i], pt[(k * NY + j) * NX + i + 1]}; lx[] += {l};
      Transfinite Curve{l} = Max(1, Floor((xs[i + 1] - xs[i]) / h + 0.5 + 1e-6)) + 1;
      If (Fabs(ys[j]) < tol)
        symc[] += {l};
      EndIf
      If (k >= 1 && cy[j] == 1)
        If (Fabs(Fabs(ys[j]) - Ly / 2) < tol)
          ext[] += {l};
        ElseIf (half == 1 && Fabs(ys[j]) < tol)
          intsym[] += {l};
        Else
          inb[] += {l};
        EndIf
      EndIf
    EndFor
  EndFor
EndFor
// lines along y: ly[(k * (NY - 1) + j) * NX + i] from (i, j) to (i, j + 1)
ly[] = {};
For k In {0:ns}
  For j In {0:NY-2}
    For i In {0:NX-1}
      l = newl; Line(l) = {pt[(k * NY + j) * NX + i], pt[(k * NY + j + 1) * NX + i]}; ly[] += {l};
      Transfinite Curve{l} = Max(1, Floor((ys[j + 1] - ys[j]) / h + 0.5 + 1e-6)) + 1;
      If (k >= 1 && cx[i] == 1)
        If (Fabs(Fabs(xs[i]) - Lx / 2) < tol)
          ext[] += {l};
        Else
          inb[] += {l};
        EndIf
      EndIf
    EndFor
  EndFor
EndFor

// one structured surface per bay and level
For k In {0:ns}
  For j In {0:NY-2}
    For i In {0:NX-2}
      c = newcl;
      Curve Loop(c) = {lx[(k * NY + j) * (NX - 1) + i], ly[(k * (NY - 1) + j) * NX + i + 1],
                       -lx[(k * NY + j + 1) * (NX - 1) + i], -ly[(k * (NY - 1) + j) * NX + i]};
      s = news; Plane Surface(s) = {c};
      Transfinite Surface{s}; Recombine Surface{s};
      If (k == 0)
        fnd[] += {s};
      ElseIf (k == ns)
        rof[] += {s};
      Else
        flo[] += {s};
      EndIf
    EndFor
  EndFor
EndFor

// columns at the column-grid points, one curve per storey
nzc = Max(1, Floor(hs / hc + 0.5 + 1e-6));
For k In {1:ns}
  For j In {0:NY-1}
    For i In {0:NX-1}
      If (cx[i] == 1 && cy[j] == 1)
        l = newl; Line(l) = {pt[((k - 1) * NY + j) * NX + i], pt[(k * NY + j) * NX + i]};
        Transfinite Curve{l} = nzc + 1;
        If (Fabs(ys[j]) < tol)
          symc[] += {l};
        EndIf
        If (half == 1 && Fabs(ys[j]) < tol)
          colsym[] += {l};
        Else
          cols[] += {l};
        EndIf
      EndIf
    EndFor
  EndFor
EndFor

// the centre point (x = 0, y = 0) of the roof (A) and of the foundation (B)
i0 = -1; j0 = -1;
For i In {0:NX-1}
  If (Fabs(xs[i]) < tol)
    i0 = i;
  EndIf
EndFor
For j In {0:NY-1}
  If (Fabs(ys[j]) < tol)
    j0 = j;
  EndIf
EndFor

Physical Surface("foundation") = {fnd[]};
If (ns > 1)
  Physical Surface("floors") = {flo[]};
EndIf
Physical Surface("roof") = {rof[]};
Physical Curve("columns") = {cols[]};
Physical Curve("ext_beams") = {ext[]};
Physical Curve("int_beams") = {inb[]};
If (#intsym[] > 0)
  Physical Curve("int_beams_sym") = {intsym[]};
EndIf
If (#colsym[] > 0)
  Physical Curve("columns_sym") = {colsym[]};
EndIf
Physical Surface("base") = {fnd[]};
Physical Point("A") = {pt[(ns * NY + j0) * NX + i0]};
Physical Point("B") = {pt[j0 * NX + i0]};
Physical Curve("sym_y") = {symc[]};
