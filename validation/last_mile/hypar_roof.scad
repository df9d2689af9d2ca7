// Hyperbolic-paraboloid roof, 400 x 400 mm, z = 80 (x/200)(y/200) mm, as a 10 mm slab.
// Exported with OpenSCAD's defaults: openscad -o hypar_roof.stl hypar_roof.scad
N = 16; A = 200; H = 80; T = 10;
function z(x, y) = H * (x / A) * (y / A);
function P(i, j, dz) = [-A + 2 * A * i / N, -A + 2 * A * j / N, z(-A + 2 * A * i / N, -A + 2 * A * j / N) + dz];
top = [for (i = [0:N]) for (j = [0:N]) P(i, j, 0)];
bot = [for (i = [0:N]) for (j = [0:N]) P(i, j, -T)];
function id(i, j) = i * (N + 1) + j;
M = (N + 1) * (N + 1);
faces = concat(
  [for (i = [0:N-1]) for (j = [0:N-1]) [id(i,j), id(i,j+1), id(i+1,j+1), id(i+1,j)]],
  [for (i = [0:N-1]) for (j = [0:N-1]) [M+id(i,j), M+id(i+1,j), M+id(i+1,j+1), M+id(i,j+1)]],
  [for (i = [0:N-1]) [id(i,0), id(i+1,0), M+id(i+1,0), M+id(i,0)]],
  [for (i = [0:N-1]) [id(i,N), M+id(i,N), M+id(i+1,N), id(i+1,N)]],
  [for (j = [0:N-1]) [id(0,j), M+id(0,j), M+id(0,j+1), id(0,j+1)]],
  [for (j = [0:N-1]) [id(N,j), id(N,j+1), M+id(N,j+1), M+id(N,j)]]
);
polyhedron(points = concat(top, bot), faces = faces);
