// The coarse correction's grid (contract.h, Derived::Coarse): nodes at the centres of cells
// that tile the walls' span, NODES of them along each axis, CELL_X/Y/Z wide (specialisation
// constants 1-6 of every coarse pass).
layout(constant_id = 1) const int NODES_X = 1;
layout(constant_id = 2) const int NODES_Y = 1;
layout(constant_id = 3) const int NODES_Z = 1;
layout(constant_id = 4) const float CELL_X = 0.08;  // m
layout(constant_id = 5) const float CELL_Y = 0.08;
layout(constant_id = 6) const float CELL_Z = 0.08;
// Built at run time: a vector of specialisation constants made invalid SPIR-V once specialised
// (the validation layer's 06719) where it was indexed or clamped against.
ivec3 nodes() { return ivec3(NODES_X, NODES_Y, NODES_Z); }
vec3 cell() { return vec3(CELL_X, CELL_Y, CELL_Z); }

// Successive over-relaxation's factor for the grid's longest side n: 2 / (1 + sin(pi / 2n)),
// the optimum for the longest mode of a side fixed at one end and free at the other (a
// column under its free surface): O(n) sweeps where Gauss-Seidel takes O(n^2).
float coarse_overrelaxation() {
  int n = max(NODES_X, max(NODES_Y, NODES_Z));
  return 2.0 / (1.0 + sin(3.14159265 / float(2 * n)));
}

int node_index(ivec3 p) { return (p.z * NODES_Y + p.y) * NODES_X + p.x; }
ivec3 node_at(int k) { return ivec3(k % NODES_X, (k / NODES_X) % NODES_Y, k / (NODES_X * NODES_Y)); }  // node_index's inverse

// The node nearest x: the centre of the cell it lies in (coarse_node_at).
int coarse_node_at(vec3 x) { return node_index(clamp(ivec3(floor((x - sim.wall_min) / cell())), ivec3(0), nodes() - 1)); }
// The eight nodes around x and their trilinear weights: node k of 8 (bits: the axes stepped).
struct CoarseCorner {
  ivec3 base;
  vec3 t;
};
CoarseCorner coarse_corner(vec3 x) {
  vec3 g = (x - sim.wall_min) / cell() - 0.5;
  vec3 b = floor(g);
  return CoarseCorner(ivec3(b), g - b);
}
int coarse_node(CoarseCorner c, int k, out float w) {
  ivec3 o = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
  w = (o.x == 1 ? c.t.x : 1.0 - c.t.x) * (o.y == 1 ? c.t.y : 1.0 - c.t.y) * (o.z == 1 ? c.t.z : 1.0 - c.t.z);
  return node_index(clamp(c.base + o, ivec3(0), nodes() - 1));
}
