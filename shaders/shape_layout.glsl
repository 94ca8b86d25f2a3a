// A drawn shape in the frame (contract.h says what it is): the ellipsoid's matrix T and its
// longest semi-axis a_max, both in particle radii, as two vec4s, (T_xx - 1, T_yy - 1, T_zz - 1,
// a_max - 1) and (T_xy, T_xz, T_yz, 0), so that zeros draw the sphere. Written by the solver's
// smoothed_positions.comp, read by the renderer (render_common.glsl); the host's twin is
// encode_shape/decode_shape in host/sim/solver.hpp.
void encode_shape(mat3 t, float longest_axis, out vec4 first, out vec4 second) {
  first = vec4(t[0][0] - 1.0, t[1][1] - 1.0, t[2][2] - 1.0, longest_axis - 1.0);
  second = vec4(t[1][0], t[2][0], t[2][1], 0.0);
}

mat3 decode_shape(vec4 first, vec4 second, out float longest_axis) {
  longest_axis = first.w + 1.0;
  return mat3(first.x + 1.0, second.x, second.y, second.x, first.y + 1.0, second.z, second.y, second.z, first.z + 1.0);
}
