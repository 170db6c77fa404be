// The ground of an elastic half-space with a rectangular excavation (a basement's pit): the
// surface z = 0 on [-Lx/2, Lx/2] x [-Ly/2, Ly/2] less the opening [-a, a] x [-b, b], the pit's
// four vertical walls down to z = -d and its bottom. Nine-node quadrilaterals (second order,
// recombined, transfinite: structured, size about h). petsc_ssi orients the elements out of the
// soil when it reads them (surface.orient_out_of_soil: +z on the ground and the bottom, into the
// pit on the walls); the same mesh as the grid generator's surface.pit.
// Parameters (-ssi_mesh_params NAME=VALUE,..., or gmsh -setnumber NAME VALUE):
//   Lx, Ly   the ground's extent (m)
//   a, b     the pit's half-widths (m)
//   d        the pit's depth (m)
//   h        element size (m)
// Physical surfaces: "ground", "walls", "bottom", and "pit" (walls and bottom: a basement's interface).
DefineConstant[ Lx = {16, Name "Parameters/Lx"}, Ly = {16, Name "Parameters/Ly"},
                a = {2, Name "Parameters/a"}, b = {2, Name "Parameters/b"},
                d = {2, Name "Parameters/d"}, h = {1, Name "Parameters/h"} ];
xs[] = {-Lx / 2, -a, a, Lx / 2};
ys[] = {-Ly / 2, -b, b, Ly / 2};
// the ground's corner points (z = 0) and the bottom's (z = -d)
For i In {0:3}
  For j In {0:3}
    p[i*4+j] = newp; Point(p[i*4+j]) = {xs[i], ys[j], 0, h};
  EndFor
EndFor
For i In {1:2}
  For j In {1:2}
    q[i*4+j] = newp; Point(q[i*4+j]) = {xs[i], ys[j], -d, h};
  EndFor
EndFor
nz = Ceil(d / h);
ground[] = {}; walls[] = {}; bottom[] = {};
// ground: the 3 x 3 patches but the middle one
For i In {0:2}
  For j In {0:2}
    If (i != 1 || j != 1)
      l1 = newl; Line(l1) = {p[i*4+j], p[(i+1)*4+j]};
      l2 = newl; Line(l2) = {p[(i+1)*4+j], p[(i+1)*4+j+1]};
      l3 = newl; Line(l3) = {p[(i+1)*4+j+1], p[i*4+j+1]};
      l4 = newl; Line(l4) = {p[i*4+j+1], p[i*4+j]};
      c = newll; Curve Loop(c) = {l1, l2, l3, l4};
      s = news; Plane Surface(s) = {c};
      n1 = Ceil((xs[i+1]-xs[i])/h); n2 = Ceil((ys[j+1]-ys[j])/h);
      Transfinite Curve{l1, l3} = n1 + 1; Transfinite Curve{l2, l4} = n2 + 1;
      Transfinite Surface{s}; Recombine Surface{s};
      ground[] += {s};
    EndIf
  EndFor
EndFor
// the bottom
l1 = newl; Line(l1) = {q[1*4+1], q[2*4+1]};
l2 = newl; Line(l2) = {q[2*4+1], q[2*4+2]};
l3 = newl; Line(l3) = {q[2*4+2], q[1*4+2]};
l4 = newl; Line(l4) = {q[1*4+2], q[1*4+1]};
c = newll; Curve Loop(c) = {l1, l2, l3, l4};
s = news; Plane Surface(s) = {c};
Transfinite Curve{l1, l3} = Ceil(2 * a / h) + 1; Transfinite Curve{l2, l4} = Ceil(2 * b / h) + 1;
Transfinite Surface{s}; Recombine Surface{s};
bottom[] += {s};
// the walls: rim (z = 0) to bottom edge (z = -d), with vertical lines at the four corners
rim[] = {p[1*4+1], p[2*4+1], p[2*4+2], p[1*4+2]};
low[] = {q[1*4+1], q[2*4+1], q[2*4+2], q[1*4+2]};
ln[] = {2 * a, 2 * b, 2 * a, 2 * b};
For k In {0:3}
  k1 = (k + 1) % 4;
  t1 = newl; Line(t1) = {rim[k], rim[k1]};
  v1 = newl; Line(v1) = {rim[k1], low[k1]};
  t2 = newl; Line(t2) = {low[k1], low[k]};
  v2 = newl; Line(v2) = {low[k], rim[k]};
  c = newll; Curve Loop(c) = {t1, v1, t2, v2};
  s = news; Plane Surface(s) = {c};
  Transfinite Curve{t1, t2} = Ceil(ln[k] / h) + 1; Transfinite Curve{v1, v2} = nz + 1;
  Transfinite Surface{s}; Recombine Surface{s};
  walls[] += {s};
EndFor
Coherence;
Physical Surface("ground") = {ground[]};
Physical Surface("walls") = {walls[]};
Physical Surface("bottom") = {bottom[]};
Physical Surface("pit") = {walls[], bottom[]};
Mesh.ElementOrder = 2;
Mesh.SecondOrderIncomplete = 0;
