// A soil region filling a rectangular pit and a footing block standing on its top (issue 42): two
// hex8 parts sharing the nodes of the footing's base, meshed with bricks of size h/2 (structured:
// Transfinite, extrusion with Layers/Recombine) so that the region's walls and bottom have nodes every
// h/2, where the nine-node soil elements of size h of the pit's surface (-ssi_mesh pit with the same a,
// b, d and -ssi_mesh_h h, or meshes/pit.geo) have theirs. z is up, the ground is z = 0, the pit's
// opening [-a, a] x [-b, b] is centred at the origin, and so is the footing's base [-c, c] x [-c, c].
// With fill = 0 only the footing is meshed (its base at z = 0): the same block on the plain half-space
// (-ssi_mesh grid -ssi_mesh_patch c,c -ssi_mesh_h h, -ssi_fem_interface base).
// Parameters (-ssi_fem_mesh_params NAME=VALUE,..., or gmsh -setnumber NAME VALUE):
//   a, b   the pit's half-widths (m)
//   d      the pit's depth (m)
//   c      the footing's half-width (m), c < a and c < b
//   hf     the footing's height (m)
//   h      the soil's element size (m): bricks of h/2; 2a/h, 2b/h, d/(h/2), (a-c)/(h/2), (b-c)/(h/2)
//          and c/(h/2) must be integers (the region's faces must carry the soil's nodes); with -ssi_mesh pit
//          d/h too (its walls take round(d/h) elements: d = 1.5 with h = 1 gives 0.75 m wall elements)
//   fill   1: the soil region and the footing; 0: the footing alone
// Physical groups
//   soil     volume: the region filling the pit (fill = 1)
//   footing  volume: the block
//   walls    surface: the region's four vertical faces (fill = 1)
//   bottom   surface: the region's bottom z = -d (fill = 1)
//   pit      surface: walls and bottom (the interface with the soil, fill = 1)
//   surface  surface: the region's top around the footing, z = 0 (free; fill = 1)
//   base     surface: the footing's base z = 0 (the interface with the soil when fill = 0)
//   top      surface: the footing's top z = hf
DefineConstant[ a = {1, Min 0.001, Name "Parameters/a"}, b = {1, Min 0.001, Name "Parameters/b"},
                d = {1, Min 0.001, Name "Parameters/d"}, c = {0.5, Min 0.001, Name "Parameters/c"},
                hf = {0.5, Min 0.001, Name "Parameters/hf"}, h = {1, Min 0.001, Name "Parameters/h"},
                fill = {1, Name "Parameters/fill", Choices {0, 1}} ];
e = h / 2;
tol = 1e-6;
// the counts of bricks, each checked to be a whole number
If (c >= a - tol || c >= b - tol)
  Error("pit_footing.geo: the footing's half-width c = %g must be below the pit's a = %g and b = %g", c, a, b);
EndIf
nc = Round(c / e); nxa = Round((a - c) / e); nyb = Round((b - c) / e); nz = Round(d / e);
nf = Max(1, Round(hf / e));
If (Fabs(nc * e - c) > tol || Fabs(nxa * e - (a - c)) > tol || Fabs(nyb * e - (b - c)) > tol ||
    Fabs(nz * e - d) > tol || Fabs(Round(2 * a / h) * h - 2 * a) > tol || Fabs(Round(2 * b / h) * h - 2 * b) > tol)
  Error("pit_footing.geo: c, a - c, b - c and d must be multiples of h/2 = %g, 2a and 2b of h = %g", e, h);
EndIf
If (fill == 1)
  xs[] = {-a, -c, c, a}; ys[] = {-b, -c, c, b}; nx[] = {nxa, 2 * nc, nxa}; ny[] = {nyb, 2 * nc, nyb};
  I0 = 0; I1 = 2;
Else
  xs[] = {-a, -c, c, a}; ys[] = {-b, -c, c, b}; nx[] = {nxa, 2 * nc, nxa}; ny[] = {nyb, 2 * nc, nyb};
  I0 = 1; I1 = 1;
EndIf
// the plan at z = 0: points P(i, j) -> pt[i * 4 + j], lines along x lx[i * 4 + j] ((i, j) -> (i + 1, j)),
// along y ly[i * 3 + j] ((i, j) -> (i, j + 1)), one transfinite quad surface per patch (i, j)
For i In {0:3}
  For j In {0:3}
    pt[i * 4 + j] = newp; Point(pt[i * 4 + j]) = {xs[i], ys[j], 0, e};
  EndFor
EndFor
For i In {0:2}
  For j In {0:3}
    lx[i * 4 + j] = newl; Line(lx[i * 4 + j]) = {pt[i * 4 + j], pt[(i + 1) * 4 + j]};
    Transfinite Curve{lx[i * 4 + j]} = nx[i] + 1;
  EndFor
EndFor
For i In {0:3}
  For j In {0:2}
    ly[i * 3 + j] = newl; Line(ly[i * 3 + j]) = {pt[i * 4 + j], pt[i * 4 + j + 1]};
    Transfinite Curve{ly[i * 3 + j]} = ny[j] + 1;
  EndFor
EndFor
soil[] = {}; walls[] = {}; bottom[] = {}; free[] = {};
For i In {I0:I1}
  For j In {I0:I1}
    cl = newcl; Curve Loop(cl) = {lx[i * 4 + j], ly[(i + 1) * 3 + j], -lx[i * 4 + j + 1], -ly[i * 3 + j]};
    s = news; Plane Surface(s) = {cl};
    Transfinite Surface{s}; Recombine Surface{s};
    If (i == 1 && j == 1)
      base = s;
    Else
      free[] += {s};
    EndIf
    If (fill == 1)
      // down to the bottom: [0] the bottom face, [1] the volume, [2..5] the sides along the loop's curves
      // (y = ys[j], x = xs[i + 1], y = ys[j + 1], x = xs[i])
      v[] = Extrude {0, 0, -d} { Surface{s}; Layers{nz}; Recombine; };
      soil[] += {v[1]}; bottom[] += {v[0]};
      If (j == 0)
        walls[] += {v[2]};
      EndIf
      If (i == 2)
        walls[] += {v[3]};
      EndIf
      If (j == 2)
        walls[] += {v[4]};
      EndIf
      If (i == 0)
        walls[] += {v[5]};
      EndIf
    EndIf
  EndFor
EndFor
f[] = Extrude {0, 0, hf} { Surface{base}; Layers{nf}; Recombine; };
If (fill == 1)
  Physical Volume("soil") = {soil[]};
  Physical Surface("walls") = {walls[]};
  Physical Surface("bottom") = {bottom[]};
  Physical Surface("pit") = {walls[], bottom[]};
  Physical Surface("surface") = {free[]};
EndIf
Physical Volume("footing") = {f[1]};
Physical Surface("base") = {base};
Physical Surface("top") = {f[0]};
