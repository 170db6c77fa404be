// Surface of an elastic half-space, nine-node quadrilaterals (second order,
// recombined), with a central rectangular patch named "load" whose edges the
// mesh follows. Parameters (set by petsc_ssi from -ssi_mesh_size/_h/_patch,
// or with gmsh -setnumber NAME VALUE):
//   Lx, Ly      full extent (m); xmin, ymin lower-left corner (0 for symmetry)
//   h           element size (m)
//   a, b        half-widths of the loaded patch (m)
DefineConstant[ Lx = {16, Name "Parameters/Lx"}, Ly = {16, Name "Parameters/Ly"},
                xmin = {-8, Name "Parameters/xmin"}, ymin = {-8, Name "Parameters/ymin"},
                h = {1, Name "Parameters/h"}, a = {1, Name "Parameters/a"},
                b = {1, Name "Parameters/b"} ];
xmax = Lx / 2; ymax = Ly / 2;
// patch corners clipped to the meshed part (quarter models start at 0)
px0 = (xmin < -a) ? -a : xmin;  py0 = (ymin < -b) ? -b : ymin;
// grid lines: xmin, px0, a, xmax (and the same in y)
xs[] = {xmin}; If (px0 > xmin) xs[] += {px0}; EndIf xs[] += {a, xmax};
ys[] = {ymin}; If (py0 > ymin) ys[] += {py0}; EndIf ys[] += {b, ymax};
nx = #xs[]; ny = #ys[];
For i In {0:nx-1}
  For j In {0:ny-1}
    p[i*ny+j] = newp; Point(p[i*ny+j]) = {xs[i], ys[j], 0, h};
  EndFor
EndFor
load[] = {}; rest[] = {};
For i In {0:nx-2}
  For j In {0:ny-2}
    l1 = newl; Line(l1) = {p[i*ny+j], p[(i+1)*ny+j]};
    l2 = newl; Line(l2) = {p[(i+1)*ny+j], p[(i+1)*ny+j+1]};
    l3 = newl; Line(l3) = {p[(i+1)*ny+j+1], p[i*ny+j+1]};
    l4 = newl; Line(l4) = {p[i*ny+j+1], p[i*ny+j]};
    c = newll; Curve Loop(c) = {l1, l2, l3, l4};
    s = news; Plane Surface(s) = {c};
    n1 = Ceil((xs[i+1]-xs[i])/h); n2 = Ceil((ys[j+1]-ys[j])/h);
    Transfinite Curve{l1, l3} = n1 + 1; Transfinite Curve{l2, l4} = n2 + 1;
    Transfinite Surface{s}; Recombine Surface{s};
    If (xs[i] >= -a - 1e-9 && xs[i+1] <= a + 1e-9 && ys[j] >= -b - 1e-9 && ys[j+1] <= b + 1e-9)
      load[] += {s};
    Else
      rest[] += {s};
    EndIf
  EndFor
EndFor
Coherence;
Physical Surface("load") = {load[]};
Physical Surface("free") = {rest[]};
Mesh.ElementOrder = 2;
Mesh.SecondOrderIncomplete = 0;
