// Soil surface with a circular footing (impedance functions of a rigid disk, to compare with
// Veletsos & Verbic): nine-node quadrilaterals (Mesh.ElementOrder 2, Recombine, every surface
// Transfinite) on [xmin, Lx/2] x [ymin, Ly/2], the disk of radius a centred at the origin.
//
// Each quadrant is the same block structure (mirrored), so the symmetry planes x = 0 and y = 0
// are element edges and a quarter (or half) model is exactly the part x, y >= 0 of the full one.
// Quadrant x, y >= 0 (q, c0, p, d below):
//   core    the corner (q, q) of a central square with bulged sides (circle arcs through
//           (c0, 0) and (q, q), crossing the axes at right angles), N x N cells; the arcs make
//           120-degree angles at (q, q), so the three cells there have 120 degrees each;
//   C1, C2  O-grid blocks between the core and the disk's rim (arcs of 45 degrees; the
//           diagonal q..a/sqrt2 is radial), N x M1 cells;          -> core + C1 + C2 = "load"
//   R1, R2  a ring from the rim to a curve through (d, 0) and P = (p, p) (again arcs crossing
//           the axes at right angles, meeting the radial diagonal at 67.5 degrees), N x M2;
//   E, Nb   blocks from that curve to the outer edges x = Lx/2 (y in [0, p]) and y = Ly/2
//           (x in [0, p]), N x K and Ky x N cells, straight grid lines y = p and x = p;
//   Z       the corner block [p, Lx/2] x [p, Ly/2], K x Ky cells.  -> R, E, Nb, Z = "free"
//   At P five cells meet (two ring, two outer, one corner block): 67.5, 67.5, 67.5, 67.5, 90.
// Sizes (per quadrant; all counts from a/h except K, Ky):
//   N  = ceil(pi a / (4 h)) cells along each 45-degree arc of the rim: 8 N around the disk,
//        rim cells pi a / (4 N) <= h. The rim of quadratic cells encloses pi a^2 (1 - 7.9e-4 / N^4)
//        (N = 3: 1 - 9.8e-6, N = 4: 1 - 3.1e-6);
//   q  = a / 2 (the core's corners on r = 0.71 a; full core about a x a), c0 = 0.566 a;
//   p  = a, d = p (1 + tan 11.25 deg) = 1.199 a; the outer blocks have the uniform cell size
//        hf = a / N (<= 4 h / pi; = h when pi a / (4 h) is an integer);
//   M1 = round(0.563 N), M2 = round(0.339 N) (at least 1): the mean radial width of C and R
//        over their mean tangential cell size;
//   K  = round((Lx/2 - a) / hf), Ky = round((Ly/2 - a) / hf).
//   Cells: N^2 + 2 N M1 under the disk ("load"), 2 N M2 + N (K + Ky) + K Ky outside ("free");
//   a = 1, h = 0.25, Lx = Ly = 6: N = 4, M1 = 2, M2 = 1, K = 8: 32 + 136 = 168 cells, 727 nodes
//   (full model 672 cells, 2785 nodes).
// Parameters (ONELAB "Parameters/..."; petsc-ssi sets Lx, Ly, xmin, ymin from -ssi_mesh_size and
// -ssi_symmetry, h from -ssi_mesh_h, a, b from -ssi_mesh_patch a,a; or gmsh -setnumber NAME VALUE):
//   Lx, Ly      full extent (m); xmin = -Lx/2 (full) or 0 (symmetry plane x = 0), ymin alike
//   h           element size (m) along the disk's rim
//   a           disk radius (m); b must equal a (or be 0)
DefineConstant[ Lx = {6, Name "Parameters/Lx"}, Ly = {6, Name "Parameters/Ly"},
                xmin = {-3, Name "Parameters/xmin"}, ymin = {-3, Name "Parameters/ymin"},
                h = {0.25, Name "Parameters/h"}, a = {1, Name "Parameters/a"},
                b = {0, Name "Parameters/b"} ];
X = Lx / 2; Y = Ly / 2;
tol = 1e-9 * Max(Lx, Ly);
If (a <= 0 || h <= 0)
  Error("disk_soil.geo: the radius a (%g) and the element size h (%g) must be positive", a, h);
EndIf
If (b > 0 && Fabs(b - a) > 1e-9 * a)
  Error("disk_soil.geo: a disk has one radius; the patch must be a,a (got a = %g, b = %g)", a, b);
EndIf
fullx = 0; fully = 0;
If (Fabs(xmin + X) <= tol)
  fullx = 1;
ElseIf (Fabs(xmin) > tol)
  Error("disk_soil.geo: xmin must be -Lx/2 = %g (full model) or 0 (symmetry plane x = 0), not %g", -X, xmin);
EndIf
If (Fabs(ymin + Y) <= tol)
  fully = 1;
ElseIf (Fabs(ymin) > tol)
  Error("disk_soil.geo: ymin must be -Ly/2 = %g (full model) or 0 (symmetry plane y = 0), not %g", -Y, ymin);
EndIf

// ---- sizes (see the header)
dc = 7.5 * Pi / 180;      // half the turn of a bulged core side: 120-degree core corners
dg = 11.25 * Pi / 180;    // half the turn of a ring's outer curve: 67.5-degree cells at P
N = Max(1, Ceil(Pi * a / (4 * h) - 1e-9));
q = 0.5 * a;
c0 = q * (1 + Tan(dc));   // where the core side crosses the axis
xc = q - q / Tan(2 * dc); // centre (xc, 0) of that arc
p = a;
d = p * (1 + Tan(dg));
xg = p - p / Tan(2 * dg);
If (X < d + 0.5 * p / N || Y < d + 0.5 * p / N)
  Error("disk_soil.geo: Lx/2 and Ly/2 (%g, %g) must exceed 1.2 a (the ring around the disk) + half a cell = %g", X, Y, d + 0.5 * p / N);
EndIf
arc = Pi * a / (4 * N);                                       // rim cell size
lc = 2 * dc * q / Sin(2 * dc);                                // length of a bulged core side
lg = 2 * dg * p / Sin(2 * dg);                                // length of a ring's outer arc
M1 = Max(1, Round(((a - c0) + (a - Sqrt(2) * q)) / 2 / ((lc / N + arc) / 2)));
M2 = Max(1, Round(((d - a) + (Sqrt(2) * p - a)) / 2 / ((lg / N + arc) / 2)));
hf = p / N;
K = Max(1, Round((X - p) / hf));
Ky = Max(1, Round((Y - p) / hf));

// ---- half axes k (0: +x, 1: +y, 2: -x, 3: -y): points at c0, a, d and the edge; segments
O = newp; Point(O) = {0, 0, 0};
For k In {0:3}
  If (k < 2 || (k == 2 && fullx) || (k == 3 && fully))
    ux = (k == 0) - (k == 2); uy = (k == 1) - (k == 3);
    L = (k % 2 == 0) ? X : Y;
    rs[] = {c0, a, d, L};
    For j In {0:3}
      ax[4 * k + j] = newp; Point(ax[4 * k + j]) = {ux * rs[j], uy * rs[j], 0};
    EndFor
    cn[] = {N, M1, M2, (k % 2 == 0) ? K : Ky};
    st = O;
    For j In {0:3}
      ac[4 * k + j] = newl; Line(ac[4 * k + j]) = {st, ax[4 * k + j]};
      Transfinite Curve{ac[4 * k + j]} = cn[j] + 1;
      st = ax[4 * k + j];
    EndFor
    cc[k] = newp; Point(cc[k]) = {ux * xc, uy * xc, 0};         // centre of the core side
    cg[k] = newp; Point(cg[k]) = {ux * xg, uy * xg, 0};         // centre of the ring's edge
  EndIf
EndFor

// one transfinite, recombined surface from the signed curves ql[] and corners qc[]
// (counter-clockwise in the quadrant x, y >= 0; reversed in mirrored quadrants so that every
// surface has the normal +z), added to load[] (ld = 1) or free[]. (A Call must end its line:
// gmsh reads the rest of the line before it runs the macro.)
Macro MakeBlock
  If (sx * sy < 0)
    ql[] = {-ql[3], -ql[2], -ql[1], -ql[0]};
    qc[] = {qc[0], qc[3], qc[2], qc[1]};
  EndIf
  cl = newcl; Curve Loop(cl) = {ql[]};
  s = news; Plane Surface(s) = {cl};
  Transfinite Surface{s} = {qc[]}; Recombine Surface{s};
  If (ld)
    load[] += {s};
  Else
    free[] += {s};
  EndIf
Return

load[] = {}; free[] = {};
r2 = Sqrt(0.5);
For ix In {0:fullx}
  For iy In {0:fully}
    sx = 1 - 2 * ix; sy = 1 - 2 * iy;       // the quadrant's signs
    kx = 2 * ix; ky = 1 + 2 * iy;           // its half axes
    Q = newp; Point(Q) = {sx * q, sy * q, 0};
    A = newp; Point(A) = {sx * a * r2, sy * a * r2, 0};
    P = newp; Point(P) = {sx * p, sy * p, 0};
    E = newp; Point(E) = {sx * X, sy * p, 0};
    F = newp; Point(F) = {sx * p, sy * Y, 0};
    Z = newp; Point(Z) = {sx * X, sy * Y, 0};
    lx = newl; Circle(lx) = {ax[4 * kx], cc[kx], Q};            // core sides
    ly = newl; Circle(ly) = {ax[4 * ky], cc[ky], Q};
    rx = newl; Circle(rx) = {ax[4 * kx + 1], O, A};             // the rim
    ry = newl; Circle(ry) = {ax[4 * ky + 1], O, A};
    gx = newl; Circle(gx) = {ax[4 * kx + 2], cg[kx], P};        // the ring's outer curve
    gy = newl; Circle(gy) = {ax[4 * ky + 2], cg[ky], P};
    dq = newl; Line(dq) = {Q, A};                               // diagonal, core to rim
    dp = newl; Line(dp) = {A, P};                               // diagonal, rim to P
    ex = newl; Line(ex) = {ax[4 * kx + 3], E};                  // outer edges
    fy = newl; Line(fy) = {ax[4 * ky + 3], F};
    pe = newl; Line(pe) = {P, E};                               // grid lines y = p, x = p
    pf = newl; Line(pf) = {P, F};
    ez = newl; Line(ez) = {E, Z};
    fz = newl; Line(fz) = {F, Z};
    Transfinite Curve{lx, ly, rx, ry, gx, gy, ex, fy} = N + 1;
    Transfinite Curve{dq} = M1 + 1;
    Transfinite Curve{dp} = M2 + 1;
    Transfinite Curve{pe, fz} = K + 1;
    Transfinite Curve{pf, ez} = Ky + 1;
    // core, C1, C2 (load); R1, R2, E, Nb, Z (free)
    ql[] = {ac[4 * kx], lx, -ly, -ac[4 * ky]};      qc[] = {O, ax[4 * kx], Q, ax[4 * ky]};  ld = 1;
    Call MakeBlock;
    ql[] = {ac[4 * kx + 1], rx, -dq, -lx};          qc[] = {ax[4 * kx], ax[4 * kx + 1], A, Q};  ld = 1;
    Call MakeBlock;
    ql[] = {ly, dq, -ry, -ac[4 * ky + 1]};          qc[] = {ax[4 * ky], Q, A, ax[4 * ky + 1]};  ld = 1;
    Call MakeBlock;
    ql[] = {ac[4 * kx + 2], gx, -dp, -rx};          qc[] = {ax[4 * kx + 1], ax[4 * kx + 2], P, A};  ld = 0;
    Call MakeBlock;
    ql[] = {ry, dp, -gy, -ac[4 * ky + 2]};          qc[] = {ax[4 * ky + 1], A, P, ax[4 * ky + 2]};  ld = 0;
    Call MakeBlock;
    ql[] = {ac[4 * kx + 3], ex, -pe, -gx};          qc[] = {ax[4 * kx + 2], ax[4 * kx + 3], E, P};  ld = 0;
    Call MakeBlock;
    ql[] = {gy, pf, -fy, -ac[4 * ky + 3]};          qc[] = {ax[4 * ky + 2], P, F, ax[4 * ky + 3]};  ld = 0;
    Call MakeBlock;
    ql[] = {pe, ez, -fz, -pf};                      qc[] = {P, E, Z, F};  ld = 0;
    Call MakeBlock;
  EndFor
EndFor
Physical Surface("load") = {load[]};
Physical Surface("free") = {free[]};
Mesh.ElementOrder = 2;
Mesh.SecondOrderIncomplete = 0;
