#pragma once
// White water, one feature in one place: its keys' parameters, and its small functions as
// white_water.glsl computes them in float (the reference's double here; shaders/white_water.h
// holds the constants both read). Its passes: sim/reference_white_water.cpp,
// gpu/gpu_white_water.cpp, shaders/white_water_advect.comp and white_water_emit.comp; its rows: sim/frame_plan.cpp (WhiteWater*)
// and gpu/buffer_plan.cpp (white_count, white_array); its keys: white_water.* in scene/keys.cpp.
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "shaders/white_water.h"

namespace pbflow {

// White water (Ihmsen et al. 2012): spray, foam and bubbles as massless secondary particles,
// born where the fluid traps air or a crest moves out fast, carried by the fluid or thrown
// ballistically, and gone when their lifetime is spent (shaders/white_water.h, docs/rendering.md).
// They read the solver's fields and write nothing of the fluid's.
struct WhiteWaterParams {
  bool enabled;       // made and drawn where a capture or an export asks for them
  int max_particles;  // at most this many alive; kChosenCapacity: derive() picks (as many as the fluid's)
  double lifetime;    // s, a particle's mean; each draws one in [0.5, 1.5] times it
  double emission;    // born per fluid particle per second where every potential is full

  static constexpr int kChosenCapacity = -1;
};


// Ihmsen et al.'s clamped ramp: 0 at `lo`, 1 from `hi`.
inline double white_ramp(double v, double lo, double hi) { return std::clamp((v - lo) / (hi - lo), 0.0, 1.0); }

// A fluid particle's potentials (white_water.h), speeds in its unit (Derived::flow_speed): the trapped
// air's closing speed, how far off it its neighbours' centre lies (kernel radii), its speed out
// along the surface's normal, and its speed.
struct WhitePotentials {
  double trapped_air, surface, outward, speed;
};

// One birth's random numbers, from the emitter's id, the birth's number and the frame: a hash
// (Wellons's lowbias32) of the three, the same bits on the GPU.
class WhiteRandom {
 public:
  WhiteRandom(uint32_t id, uint32_t birth, uint32_t frame)
      : seed_(hash((id * WHITE_MOST_BORN + birth) ^ hash(frame))) {}
  glm::dvec3 offset() const { return {unit(1), unit(2), unit(3)}; }  // in [0, 1)^3
  double life() const { return unit(4); }
  double count() const { return unit(0); }  // the stochastic rounding of the births' number (birth 0's)

  static uint32_t hash(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
  }

 private:
  double unit(uint32_t stream) const { return double(hash(seed_ + stream) >> 8) / double(1u << 24); }
  uint32_t seed_;
};

// The particles a fluid particle gives birth to this frame: `rate` (emission times the frame's
// time) times its potentials, rounded up or down at random, at most WHITE_MOST_BORN.
inline uint32_t white_water_born(const WhitePotentials& p, double rate, uint32_t id, uint32_t frame) {
  const double crest = white_ramp(p.surface, WHITE_SURFACE_MIN, WHITE_SURFACE_MAX) *
                       white_ramp(p.outward, WHITE_CREST_MIN, WHITE_CREST_MAX);
  const double expected = rate * white_ramp(p.speed, WHITE_SPEED_MIN, WHITE_SPEED_MAX) *
                          (white_ramp(p.trapped_air, WHITE_TRAPPED_AIR_MIN, WHITE_TRAPPED_AIR_MAX) + crest);
  return uint32_t(std::min(std::floor(expected + WhiteRandom(id, 0, frame).count()), double(WHITE_MOST_BORN)));
}

// Spray, foam or bubble, from the fluid's density around it over rho0.
inline uint32_t white_water_kind(double density_fraction) {
  return density_fraction < WHITE_SPRAY_BELOW ? WHITE_SPRAY : density_fraction > WHITE_BUBBLE_ABOVE ? WHITE_BUBBLE : WHITE_FOAM;
}

}  // namespace pbflow
