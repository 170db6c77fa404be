// The paper's building (meshes/building.geo, full model) on a basement: a block of bricks under the whole
// foundation slab, from z = 0 down to z = -d, made by extruding the slab's surfaces, so that its top nodes are
// the slab's nodes (the columns stand on the slab, the slab on the block). It fills a pit of the
// building's plan (-ssi_mesh pit -ssi_mesh_params a=nbx sx/2,b=nby sy/2,d=d) and is coupled to the soil on its
// walls and bottom (-ssi_fem_interface bwalls,bbottom). Its bricks are the slab's h in plan and d/nzb in
// depth: the soil's nine-node elements on the pit need h_soil = 2 h, and nzb = 2 x the pit generator's
// elements down the walls (round(d / h_soil), halves to even: d = 3, h_soil = 1.2 -> 2, nzb = 4).
// Parameters: those of building.geo (half must be 0: a surface with a pit takes no symmetry plane), and
//   d     the basement's depth [m] (3)
//   nzb   bricks through the depth (4)
// Physical groups: those of building.geo, and
//   basement  volume: the block's bricks
//   bwalls    surface: its four vertical faces
//   bbottom   surface: its bottom z = -d
//   bpit      surface: both (the interface with the soil)
DefineConstant[
  nbx = {4, Min 1, Max 1000, Step 1, Name "Parameters/nbx"}, nby = {3, Min 1, Max 1000, Step 1, Name "Parameters/nby"},
  sx = {3.6, Min 0.001, Name "Parameters/sx"}, sy = {3.6, Min 0.001, Name "Parameters/sy"},
  ns = {3, Min 1, Max 1000, Step 1, Name "Parameters/ns"}, hs = {3.0, Min 0.001, Name "Parameters/hs"},
  h = {0.6, Min 0.001, Name "Parameters/h"}, hc = {0.3, Min 0.001, Name "Parameters/hc"},
  half = {0, Name "Parameters/half", Choices {0}},
  d = {3, Min 0.001, Name "Parameters/d"}, nzb = {4, Min 1, Max 1000, Step 1, Name "Parameters/nzb"} ];
Include "building.geo";
Extrude {0, 0, -d} { Surface{fnd[]}; Layers{nzb}; Recombine; }
e = 1e-3 * h;
Physical Volume("basement") = Volume In BoundingBox {-Lx / 2 - e, -Ly / 2 - e, -d - e, Lx / 2 + e, Ly / 2 + e, e};
bw[] = Surface In BoundingBox {-Lx / 2 - e, -Ly / 2 - e, -d - e, -Lx / 2 + e, Ly / 2 + e, e};
bw[] += Surface In BoundingBox {Lx / 2 - e, -Ly / 2 - e, -d - e, Lx / 2 + e, Ly / 2 + e, e};
bw[] += Surface In BoundingBox {-Lx / 2 - e, -Ly / 2 - e, -d - e, Lx / 2 + e, -Ly / 2 + e, e};
bw[] += Surface In BoundingBox {-Lx / 2 - e, Ly / 2 - e, -d - e, Lx / 2 + e, Ly / 2 + e, e};
bb[] = Surface In BoundingBox {-Lx / 2 - e, -Ly / 2 - e, -d - e, Lx / 2 + e, Ly / 2 + e, -d + e};
Physical Surface("bwalls") = {bw[]};
Physical Surface("bbottom") = {bb[]};
Physical Surface("bpit") = {bw[], bb[]};
