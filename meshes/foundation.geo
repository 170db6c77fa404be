// The paper's concrete foundation block (Romero, Galvin & Dominguez, Sec. 5.1):
// 1 m x 1 m x 0.5 m, 400 eight-node bricks (10 x 10 x 4), centred at x = y = 0,
// base at z = 0 (the soil interface), top at z = 0.5. z is up.
// Built by extrusion with Layers/Recombine, so every cell is a hex8. The block
// is made of two halves (x < 0, x > 0) so that the top splits into the
// physical groups "top_left" and "top_right" (antisymmetric load case).
// Mesh with: gmsh -3 foundation.geo   (petsc_ssi meshes it through the gmsh API)
lx = 1.0; ly = 1.0; h = 0.5;
nx = 10; ny = 10; nz = 4;   // bricks per direction (nx even)

Point(1) = {-lx/2, -ly/2, 0};
Point(2) = {0,     -ly/2, 0};
Point(3) = { lx/2, -ly/2, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Transfinite Curve{1, 2} = nx/2 + 1;

// Sweep the two base edges along y: two base quads (left, right).
left[]  = Extrude {0, ly, 0} { Curve{1}; Layers{ny}; Recombine; };
right[] = Extrude {0, ly, 0} { Curve{2}; Layers{ny}; Recombine; };
// Sweep the base quads up: two bricks of hexahedra.
vl[] = Extrude {0, 0, h} { Surface{left[1]};  Layers{nz}; Recombine; };
vr[] = Extrude {0, 0, h} { Surface{right[1]}; Layers{nz}; Recombine; };
Coherence;

// Extrude of a surface returns: [0] top surface, [1] volume, [2..] lateral sides.
Physical Surface("base") = {left[1], right[1]};
Physical Surface("top") = {vl[0], vr[0]};
Physical Surface("top_left") = {vl[0]};
Physical Surface("top_right") = {vr[0]};
Physical Volume("block") = {vl[1], vr[1]};
