// Soil surface of the paper's foundation example (Romero, Galvin & Dominguez,
// Sec. 5.1, Fig. 7a): nine-node quadrilaterals on the square [-L, L]^2
// (L = 2.5 m: 145 elements), graded towards a central square [-a, a]^2 of
// n x n elements under the block whose nodes match the block's base nodes
// (a = 0.5 m, h = 0.2 m: 5 x 5 nine-node elements, nodes every 0.1 m = the
// 11 x 11 base nodes of the 10 x 10 x 4 hex8 block). Around it four
// trapezoids of n (along the block's side) x m (outwards, sizes growing by
// the factor r) elements: 25 + 4 x 5 x 6 = 145 elements.
// Parameters (set by petsc_ssi from -ssi_mesh_size Lx,Ly (Lx = 2L),
// -ssi_mesh_patch a,b (a = b) and -ssi_mesh_h h; m and r with gmsh
// -setnumber): full model only (no symmetry planes).
DefineConstant[ Lx = {5, Name "Parameters/Lx"}, Ly = {5, Name "Parameters/Ly"},
                xmin = {-2.5, Name "Parameters/xmin"}, ymin = {-2.5, Name "Parameters/ymin"},
                h = {0.2, Name "Parameters/h"}, a = {0.5, Name "Parameters/a"},
                b = {0.5, Name "Parameters/b"}, m = {6, Name "Parameters/m"},
                r = {1.25, Name "Parameters/r"} ];
L = Lx / 2;
n = Round(2 * a / h);
If (n < 1)
  Error("foundation_soil.geo: the central square needs 2a/h >= 1 elements");
EndIf
// inner corners 1-4, outer corners 5-8 (counter-clockwise from (-,-))
Point(1) = {-a, -a, 0}; Point(2) = {a, -a, 0}; Point(3) = {a, a, 0}; Point(4) = {-a, a, 0};
Point(5) = {-L, -L, 0}; Point(6) = {L, -L, 0}; Point(7) = {L, L, 0}; Point(8) = {-L, L, 0};
For i In {0:3}
  in[i] = newl; Line(in[i]) = {1 + i, 1 + (i + 1) % 4};       // inner edges
  out[i] = newl; Line(out[i]) = {5 + i, 5 + (i + 1) % 4};     // outer edges
  rad[i] = newl; Line(rad[i]) = {1 + i, 5 + i};               // inner -> outer corner
EndFor
Transfinite Curve{in[], out[]} = n + 1;
Transfinite Curve{rad[]} = m + 1 Using Progression r;
c = newll; Curve Loop(c) = {in[0], in[1], in[2], in[3]};
centre = news; Plane Surface(centre) = {c};
Transfinite Surface{centre}; Recombine Surface{centre};
ring[] = {};
For i In {0:3}
  c = newll; Curve Loop(c) = {in[i], rad[(i + 1) % 4], -out[i], -rad[i]};
  s = news; Plane Surface(s) = {c};
  Transfinite Surface{s}; Recombine Surface{s};
  ring[] += {s};
EndFor
Physical Surface("interface") = {centre};
Physical Surface("free") = {ring[]};
Mesh.ElementOrder = 2;
Mesh.SecondOrderIncomplete = 0;
