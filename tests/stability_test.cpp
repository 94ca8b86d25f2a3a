// The linear stability numbers behind the relaxation, the lambda averages and the explicit
// terms' caps (sim/stability.hpp; docs/physics.md, "Relaxed Jacobi passes").

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "shaders/contract.h"
#include "sim/stability.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

// The relaxation schedule keeps every mode's combined gain within [0, gain] (a mode
// corrected past its own error is what made energy), for any number of passes.
TEST(Stability, JacobiScheduleNeverOvercorrectsAMode) {
  const double gain_max = jacobi_gain_max(2.0, 0.01);
  std::printf("  largest gain of one unrelaxed pass at h = 2 spacings: %.3f\n", gain_max);
  EXPECT_GT(gain_max, 4.0 / 3.0) << "then the unrelaxed solver would have been stable";
  for (int passes = 1; passes <= 6; ++passes) {
    auto w = jacobi_schedule(passes, 1.0, gain_max);
    ASSERT_EQ(w.size(), size_t(passes));
    for (double lambda = 0; lambda <= gain_max; lambda += gain_max / 500) {
      double left = 1;
      for (double wk : w) left *= 1 - wk * lambda;
      EXPECT_GE(1 - left, -1e-12) << passes << " passes, mode gain " << lambda;
      EXPECT_LE(1 - left, 1 + 1e-12) << passes << " passes, mode gain " << lambda;
    }
  }
}

// Smoothing lambda (two averages over the neighbours, constraint_smooth.comp) cuts the
// worst mode's gain ~2.9x and leaves the long modes', which carry the compression, so a
// pair's passes can be as much bolder; an even count never turns a mode's correction
// around, a single average does (why the scene refuses odd counts).
TEST(Stability, SmoothedLambdaKeepsLongModesAndTamesTheWorst) {
  const double plain = jacobi_gain_max(2.0, 0.01), smoothed = jacobi_gain_max(2.0, 0.01, 0, 2);
  const double long_plain = jacobi_long_mode_gain(2.0, 0.01, 0), long_smoothed = jacobi_long_mode_gain(2.0, 0.01, 2);
  std::printf("  largest gain %.3f -> %.3f smoothed; long modes %.3f -> %.3f per (k spacing)^2; least gain with "
              "0, 1, 2 averages %.4f, %.4f, %.4f\n",
              plain, smoothed, long_plain, long_smoothed, jacobi_gain_min(2.0, 0.01, 0), jacobi_gain_min(2.0, 0.01, 1),
              jacobi_gain_min(2.0, 0.01, 2));
  EXPECT_LT(smoothed, plain / 2.5);
  EXPECT_NEAR(long_smoothed / long_plain, 1.0, 0.01);
  EXPECT_GT(long_plain / plain, 0.9) << "the long modes' gain per k^2 is near the worst mode's";
  EXPECT_GE(jacobi_gain_min(2.0, 0.01, 2), -1e-3);
  EXPECT_GE(jacobi_gain_min(2.0, 0.01, 4), -1e-3);
  EXPECT_LT(jacobi_gain_min(2.0, 0.01, 1), -0.1);
  // Squeezed, the smoothed pass's gain grows less than the plain one's: lambda's factor covers it.
  for (double c : {0.1, 0.25, 0.5, 1.0})
    EXPECT_LE(jacobi_gain_max(2.0, 0.01, c, 2) / (1 + kCompressedGain * c), 1.03 * smoothed) << "compression " << c;
}

// Pairs of passes run smoothed at the smoothed model's relaxation; a single iteration runs as
// a pair's first pass does (smoothed, at 1 / the smoothed model's gain) with the coarse
// correction at its own strength; an odd count's last pass after pairs runs unsmoothed at the
// plain model's, and so does a single one where lambda is not smoothed, with no coarse
// correction (Derived::constraint_schedule says why).
TEST(Stability, PassesAreSmoothedButAnOddCountsLast) {
  Derived d = derive(load_scene("dam_break"));
  ASSERT_EQ(d.solver.lambda_smoothing, 2);
  for (int passes = 1; passes <= 4; ++passes) {
    auto schedule = d.constraint_schedule(passes);
    ASSERT_EQ(schedule.size(), size_t(passes));
    for (int k = 0; k < passes; ++k) {
      const bool last_of_odd = passes > 1 && passes % 2 && k == passes - 1;
      const double relax = passes == 1 ? 1 / d.paired_gain_max : last_of_odd ? 1 / d.jacobi_gain_max : 1.5 / d.paired_gain_max;
      EXPECT_EQ(schedule[k].smoothed, !last_of_odd) << passes << " passes, pass " << k;
      EXPECT_NEAR(schedule[k].relaxation, relax, 1e-12) << passes << " passes, pass " << k;
    }
  }
  const Derived single = derive(load_scene("dam_break", {"solver.iterations=1"}));
  EXPECT_EQ(single.coarse.strength, COARSE_LONE_STRENGTH);
  const Derived single_unsmoothed = derive(load_scene("dam_break", {"solver.iterations=1", "solver.lambda_smoothing=0"}));
  EXPECT_EQ(single_unsmoothed.coarse.strength, 0.0);
  const auto plain = single_unsmoothed.constraint_schedule(1);
  ASSERT_EQ(plain.size(), 1u);
  EXPECT_FALSE(plain[0].smoothed);
  EXPECT_NEAR(plain[0].relaxation, 1 / single_unsmoothed.jacobi_gain_max, 1e-12);
  EXPECT_EQ(derive(load_scene("dam_break")).coarse.strength, COARSE_STRENGTH);
}

// From three iterations on the pairs get four lambda averages where a step moves at most h,
// two where it moves more (default_smoothing: past h four made energy where two made none);
// a scene's own count stands, and the pairs' relaxation follows the count used. The run
// warns of the same travel.
TEST(Stability, FourAveragesOnlyWhereAStepStaysWithinH) {
  auto derived = [](std::vector<std::string> o) { return derive(load_scene("dam_break", o)); };
  const Derived real_time = derived({"solver.iterations=4"});
  EXPECT_NEAR(real_time.travel, 0.92, 0.01);  // 0.02 m, 60 fps x 2: the fall moves 0.92 h a step
  EXPECT_EQ(real_time.solver.lambda_smoothing, 4);
  EXPECT_DOUBLE_EQ(real_time.paired_gain_max, jacobi_gain_max(2.0, 0.01, 0.0, 4));
  EXPECT_EQ(derived({"solver.iterations=3"}).solver.lambda_smoothing, 4);
  EXPECT_EQ(derived({"solver.iterations=2"}).solver.lambda_smoothing, 2);
  // Left out, the substeps are chosen so that a step stays within h (chosen_substeps): 3 here.
  EXPECT_EQ(load_scene("dam_break", {"particle_spacing=0.0137"}).solver.substeps, 3);
  EXPECT_EQ(load_scene("dam_break").solver.substeps, 2);
  EXPECT_EQ(load_scene("dam_break", {"fps=240"}).solver.substeps, 1);
  EXPECT_EQ(load_scene("dam_break", {"particle_spacing=0.01"}).solver.substeps, 4);
  const Scene fine_scene =
      load_scene("dam_break", {"solver.iterations=4", "particle_spacing=0.0137", "solver.substeps=2"});
  const Derived fine = derive(fine_scene);  // 1.35 h a step, which the run warns of
  EXPECT_GT(fine.travel, 1.0);
  const std::string warning = time_step_warning(fine_scene, fine);
  EXPECT_NE(warning.find("1.35 kernel radii per step"), std::string::npos) << warning;
  EXPECT_NE(warning.find("solver.substeps=3 keeps it within one"), std::string::npos) << warning;
  EXPECT_EQ(time_step_warning(load_scene("dam_break"), real_time), "");
  EXPECT_EQ(fine.solver.lambda_smoothing, 2);
  EXPECT_DOUBLE_EQ(fine.paired_gain_max, jacobi_gain_max(2.0, 0.01, 0.0, 2));
  const Derived fine_small_steps = derived({"solver.iterations=4", "particle_spacing=0.0137", "solver.substeps=4"});
  EXPECT_EQ(fine_small_steps.solver.lambda_smoothing, 4);
  EXPECT_EQ(derived({"solver.iterations=4", "solver.lambda_smoothing=2"}).solver.lambda_smoothing, 2);
  EXPECT_EQ(derived({"solver.iterations=1", "solver.lambda_smoothing=4"}).solver.lambda_smoothing, 4);
  EXPECT_EQ(derived({"solver.iterations=3", "solver.lambda_smoothing=0"}).solver.lambda_smoothing, 0);
}

// lambda's 1 / (1 + kCompressedGain C) holds a squeezed lattice's largest gain at its value
// at rho0 (within 3 % up to C = 1), and is not much more than that: 1 / (1 + C) was, and the column
// it could not hold collapsed (pbf@1).
TEST(Stability, CompressedFluidIsNotOvercorrected) {
  const double at_rest = jacobi_gain_max(2.0, 0.01);
  for (double c : {0.05, 0.1, 0.2, 0.4, 0.8, 1.0}) {
    const double squeezed = jacobi_gain_max(2.0, 0.01, c);
    std::printf("  compression %.2f: largest gain %.3f (%.3f of rest), after the factor %.3f\n", c, squeezed,
                squeezed / at_rest, squeezed / at_rest / (1 + kCompressedGain * c));
    EXPECT_GT(squeezed, at_rest) << "compression " << c << ": more neighbours, more gain";
    EXPECT_LE(squeezed / (1 + kCompressedGain * c), 1.03 * at_rest) << "compression " << c;
    EXPECT_GE(squeezed / (1 + kCompressedGain * c), 0.85 * at_rest) << "compression " << c;
  }
}

// The explicit terms' stiffness grows with the neighbours inside h: on a lattice squeezed
// to 3x rho0 the LDC force is 8x as stiff as at rest and the dashpot 2.4x, far past their
// limits (dam break at 0.01 m: the bottom of the column reached 2-5x rho0 and both blew
// up). Capped as the passes cap them (Derived::ldc_room, damping_limit), the LDC force at
// its default strength stays within kLdcCap of its limit, and the dashpot, at the default
// and at the largest accepted damping, leaves its fastest mode within 1.5 (driven past 2).
TEST(Stability, ExplicitTermsKeepTheirLimitsInSqueezedFluid) {
  const Derived d = derive(load_scene("dam_break", {"solver.method=ldc"}));
  const double ldc_rest = ldc_stiffness_max(2.0), damping_rest = damping_gain_max(2.0);
  const double strength = d.ldc_k / d.ldc_k_limit;
  std::printf("  at rest: LDC stiffness %.3f, dashpot eigenvalue %.3f; ldc_room %.3f, damping_limit %.3f\n", ldc_rest,
              damping_rest, d.ldc_room, d.damping_limit);
  EXPECT_LT(0.3 * damping_rest, 2.0) << "solver.damping's upper bound must not drive a mode at rest";
  for (double c : {0.25, 0.5, 1.0, 2.0, 3.0, 4.0}) {
    const double rho = lattice_density(2.0, c);
    const double ldc = strength * ldc_stiffness_max(2.0, c) / ldc_rest;  // fraction of the limit
    const double ldc_capped = ldc * std::min(1.0, d.ldc_room / (rho * rho));
    const double eigenvalue = damping_gain_max(2.0, c);
    std::printf("  compression %.2f (rho/rho0 %.3f): LDC %.2f of its limit, capped %.2f; dashpot 0.3: %.2f, capped %.2f\n",
                c, rho, ldc, ldc_capped, 0.3 * eigenvalue, std::min(0.3, d.damping_limit / rho) * eigenvalue);
    EXPECT_LE(ldc_capped, kLdcCap + 1e-9) << "compression " << c;
    for (double damping : {0.2, 0.3}) EXPECT_LE(std::min(damping, d.damping_limit / rho) * eigenvalue, 1.5 + 1e-9) << "compression " << c;
  }
  // Uncapped, both pass their limits in the squeeze the dam break at 0.01 m reached.
  EXPECT_GT(strength * ldc_stiffness_max(2.0, 1.0) / ldc_rest, 1.0);
  EXPECT_GT(0.3 * damping_gain_max(2.0, 2.0), 2.0);
}


// LDC's K is a fraction of what the step carries: it scales as 1/dt^2, and a stated K
// past the limit is refused with a message naming it.
TEST(Stability, LdcStiffnessScalesWithTheStep) {
  Derived two = derive(load_scene("dam_break", {"solver.method=ldc", "solver.substeps=2"}));
  Derived four = derive(load_scene("dam_break", {"solver.method=ldc", "solver.substeps=4"}));
  EXPECT_NEAR(four.ldc_k / two.ldc_k, 4.0, 1e-9);
  EXPECT_NEAR(two.ldc_k, two.solver.ldc_strength * two.ldc_k_limit, 1e-9);
  // Independent of the spacing: the limit depends on h / spacing only.
  Derived coarse = derive(load_scene("dam_break", {"solver.method=ldc", "particle_spacing=0.04"}));
  EXPECT_NEAR(coarse.ldc_k_limit, two.ldc_k_limit, 1e-9 * two.ldc_k_limit);
  try {
    derive(load_scene("dam_break", {"solver.method=ldc", "solver.ldc_k=" + std::to_string(1.01 * two.ldc_k_limit)}));
    ADD_FAILURE() << "a K past the stability limit was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("stability limit"), std::string::npos) << e.what();
  }
}

// The dashpot (viscosity_vorticity.comp) on the reference, XSPH off so that only the
// dashpot acts: an 8^3 lattice block (spacing 0.02 m) at `corner` in the hydrostatic tank
}  // namespace
}  // namespace pbflow
