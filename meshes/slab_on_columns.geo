// A concrete slab on four columns: the smallest structure that mixes shells and frames.
// Slab Lx x Ly at height H (four-node shells, Recombine), columns from z = 0 to z = H at the
// four corners (two-node frames). The columns' top points ARE the slab's corner points, so
// the meshes share nodes there (monolithic joints). z is up.
// Physical groups: "slab" (surface: the shell part), "columns" (curves: the frame part),
// "base" (points: the column feet), "top_corner" (point: the slab corner above column 3).
// Parameters (gmsh -setnumber or ONELAB): Lx, Ly, H, nx, ny, nz (elements per side/column).
DefineConstant[ Lx = {4.0, Name "Parameters/Lx", Min 1e-6}, Ly = {3.0, Name "Parameters/Ly", Min 1e-6},
                H = {3.0, Name "Parameters/H", Min 1e-6}, nx = {8, Name "Parameters/nx", Min 1, Step 1},
                ny = {6, Name "Parameters/ny", Min 1, Step 1}, nz = {6, Name "Parameters/nz", Min 1, Step 1} ];
// (Min, Step: the values petsc-ssi accepts in -ssi_fem_mesh_params; gmsh itself does not check)

Point(1) = {0, 0, H};   Point(2) = {Lx, 0, H};
Point(3) = {Lx, Ly, H}; Point(4) = {0, Ly, H};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = nx + 1;
Transfinite Curve{2, 4} = ny + 1;
Transfinite Surface{1};
Recombine Surface{1};

Point(5) = {0, 0, 0};   Point(6) = {Lx, 0, 0};
Point(7) = {Lx, Ly, 0}; Point(8) = {0, Ly, 0};
Line(5) = {5, 1}; Line(6) = {6, 2}; Line(7) = {7, 3}; Line(8) = {8, 4};
Transfinite Curve{5, 6, 7, 8} = nz + 1;

Physical Surface("slab") = {1};
Physical Curve("columns") = {5, 6, 7, 8};
Physical Point("base") = {5, 6, 7, 8};
Physical Point("top_corner") = {3};
