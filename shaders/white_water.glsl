// White water's small functions in float (host/sim/white_water.hpp is the reference's double;
// white_water.h the constants both read). The includer has included common.glsl.
#include "white_water.h"

// Ihmsen et al.'s clamped ramp: 0 at lo, 1 from hi.
float white_ramp(float v, float lo, float hi) { return clamp((v - lo) / (hi - lo), 0.0, 1.0); }

// Wellons's lowbias32: the same bits as WhiteRandom::hash.
uint white_hash(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
uint white_seed(uint id, uint birth, uint frame) { return white_hash((id * WHITE_MOST_BORN + birth) ^ white_hash(frame)); }
// Stream k of a birth's random numbers, in [0, 1) with 24 bits (exact in float).
float white_unit(uint seed, uint k) { return float(white_hash(seed + k) >> 8) / 16777216.0; }

// white_water_born: the births this frame, from the potentials (white_water.h's units).
uint white_water_born(float trapped_air, float surface, float outward, float speed, float rate, uint id, uint frame) {
  float crest = white_ramp(surface, WHITE_SURFACE_MIN, WHITE_SURFACE_MAX) * white_ramp(outward, WHITE_CREST_MIN, WHITE_CREST_MAX);
  float expected = rate * white_ramp(speed, WHITE_SPEED_MIN, WHITE_SPEED_MAX) *
                   (white_ramp(trapped_air, WHITE_TRAPPED_AIR_MIN, WHITE_TRAPPED_AIR_MAX) + crest);
  return uint(min(floor(expected + white_unit(white_seed(id, 0u, frame), 0u)), float(WHITE_MOST_BORN)));
}

uint white_water_kind(float density_fraction) {
  return density_fraction < WHITE_SPRAY_BELOW ? WHITE_SPRAY : density_fraction > WHITE_BUBBLE_ABOVE ? WHITE_BUBBLE : WHITE_FOAM;
}
