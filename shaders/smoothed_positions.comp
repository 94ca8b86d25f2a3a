#version 450
// The particles' smoothed positions and drawn shapes, for drawing the fluid's surface (Yu &
// Turk 2013). The position: x_i + POSITION_SMOOTHING (mean_j x_j - x_i), the mean weighted by
// 1 - (r/h)^3 over the neighbours and their images behind the walls, i itself included.
// Inside the fluid the mean is the particle's own place; at the free surface it lies inward,
// so a surface's particles are drawn closer to a plane: a lattice's rows and columns, a
// spacing apart, no longer show as bands, and a settled top lies flatter. The walls' images
// keep a particle at a wall where it is. The shape: an ellipsoid from the same neighbourhood's
// covariance (shaders/contract.h), a sphere inside the fluid and at the walls, a disc at a
// free surface, stretched along a sheet that a flow has pulled apart, whose spheres alone
// left a ridge per row. Written once a frame where the capture asks
// (Solver::set_smoothed_positions).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"
#include "shape_layout.glsl"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x;
layout(std430, binding = 2) writeonly buffer XSmooth { vec4 x_smooth[]; };
layout(std430, binding = 3) writeonly buffer Shape { vec4 shape[]; };  // two a particle
#define OBSTACLES_BINDING 6
#define NEIGHBOUR_BINDING 4
#define CREASES_BINDING 7
#define NEIGHBOUR_CAPACITY_ID 1
#include "neighbours.glsl"

// One Jacobi rotation in the (p, q) plane of a symmetric 3 x 3 matrix, r its third index: zeroes
// a_pq, updating the five elements it touches and the eigenvectors' columns p and q.
void jacobi_rotate(inout float app, inout float aqq, inout float apq, inout float arp, inout float arq, inout vec3 vp,
                   inout vec3 vq) {
  if (apq == 0.0) return;
  float theta = 0.5 * (aqq - app) / apq;
  float t = (theta >= 0.0 ? 1.0 : -1.0) / (abs(theta) + sqrt(theta * theta + 1.0));
  float c = inversesqrt(t * t + 1.0), s = t * c, tau = s / (1.0 + c);
  app -= t * apq;
  aqq += t * apq;
  apq = 0.0;
  float g = arp;
  arp -= s * (arq + tau * arp);
  arq += s * (g - tau * arq);
  vec3 w = vp;
  vp -= s * (vq + tau * vp);
  vq += s * (w - tau * vq);
}

// Jacobi sweeps diagonalise the symmetric c: c = v diag(l) v^T, v's columns unit eigenvectors.
void symmetric_eigen(mat3 c, out vec3 l, out mat3 v) {
  float d0 = c[0][0], d1 = c[1][1], d2 = c[2][2], o01 = c[1][0], o02 = c[2][0], o12 = c[2][1];
  vec3 v0 = vec3(1, 0, 0), v1 = vec3(0, 1, 0), v2 = vec3(0, 0, 1);
  for (int sweep = 0; sweep < SHAPE_SWEEPS; ++sweep) {
    jacobi_rotate(d0, d1, o01, o02, o12, v0, v1);
    jacobi_rotate(d0, d2, o02, o01, o12, v0, v2);
    jacobi_rotate(d1, d2, o12, o01, o02, v1, v2);
  }
  l = vec3(d0, d1, d2);
  v = mat3(v0, v1, v2);
}

// Particle i's drawn shape from its neighbourhood's covariance (in h^2) and its count
// (shaders/contract.h); zeros draw the sphere.
void write_shape(uint i, mat3 covariance, int count) {
  vec3 l;
  mat3 axes;
  symmetric_eigen(covariance, l, axes);
  float largest = max(l.x, max(l.y, l.z));
  if (count < SHAPE_MIN_NEIGHBOURS || !(largest > 0.0)) {
    encode_shape(mat3(1.0), 1.0, shape[2 * i], shape[2 * i + 1]);
    return;
  }
  vec3 a = max(l, vec3(largest / SHAPE_MAX_STRETCH));
  a /= pow(a.x * a.y * a.z, 1.0 / 3.0);  // the sphere's volume
  mat3 t = axes * mat3(a.x * a.x, 0, 0, 0, a.y * a.y, 0, 0, 0, a.z * a.z) * transpose(axes);
  encode_shape(t, max(a.x, max(a.y, a.z)), shape[2 * i], shape[2 * i + 1]);
}

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec3 xi = imageLoad(x, int(i)).xyz;
  Mirrors mirrors = neighbour_mirrors(i, xi);
  // The position's mean weighs the nearest most (position_weight); the covariance weighs the
  // neighbourhood nearly flat to h (smoothing_weight), so that it sees a sheet's rows pulled
  // 1.75 spacings apart. Offsets in units of h keep the second moments near 1 in float. No
  // branch in the loop: a CPU device runs both sides for every lane, and a `continue` past
  // the zero weights made the pass half as slow again (docs/performance.md).
  vec3 towards = vec3(0.0), first = vec3(0.0), square = vec3(0.0), cross = vec3(0.0);  // second moments
  float position_weights = 0.0, weights = 0.0;
  int count = 0, image;
  FOR_EACH_NEIGHBOUR(i, xi, mirrors, j, image) {
    vec3 d = mirror(mirrors, image, j, imageLoad(x, int(j)).xyz) - xi;
    float w = smoothing_weight(d), wp = position_weight(d);
    count += int(w > 0.0);
    d /= sim.h;
    towards += wp * d;
    position_weights += wp;
    first += w * d;
    square += w * d * d;
    cross += w * d.xxy * d.yzz;
    weights += w;
  }
  x_smooth[i] = vec4(xi + float(POSITION_SMOOTHING) * sim.h * towards / position_weights, 0.0);
  vec3 mean = first / weights;
  mat3 second = mat3(square.x, cross.x, cross.y, cross.x, square.y, cross.z, cross.y, cross.z, square.z);
  write_shape(i, second / weights - outerProduct(mean, mean), count);
}
