// The steps the biaxial (disks, biaxial.cpp) and triaxial (spheres,
// triaxial.cpp) protocols share, written once.
//
// Consolidation: every wall servoed at σ3; phase 0
// frictionless (a packing without friction finds its densest state), phase
// 1 friction on, each until static — every wall stress within
// test.consolidation_tolerance of σ3 and the unbalanced-force ratio below
// test.consolidation_unbalanced, checked every kCheckEvery steps. Light
// damping relaxes slow collective modes fast, but where the residual is
// noise rather than slow modes (a very low σ3, where round-off forces are a
// sizeable share of the contact forces) it leaves that noise undamped: if a
// quarter of the budget has not brought the sample to rest, the rest runs
// at critical damping (the paper's start point) — a quarter in simulated
// time of the undamped step, so later where contact dashpots shrink the
// step (run_consolidation says why). A frictionless phase not static by
// then ends there, at half the budget at the latest, and friction goes on.
//
// Private to src/scene. The consolidation's critical-damping switch and
// frictionless cut (critical_damping_after, frictionless_phase_cut,
// consolidation_step_shrink), which the decks' stage 1 (src/upscaling)
// shares, are public: demcal/scene/biaxial.hpp.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

#include "demcal/io/format.hpp"
#include "demcal/kernel/world.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/consolidation_progress.hpp"
#include "empty_slab.hpp"

namespace demcal::detail {

/// The step and damping consolidation settles with: α = consolidation_alpha
/// (0.2, the paper's start step, shrunk where contact dashpots lower the
/// stable step) for particles with radii in [r_min, r_max], light damping
/// kConsolidationDampingRatio on translation and rotation (biaxial.cpp says
/// why), the config's rotation lock.
inline AlgorithmSpec consolidation_settings(const SceneConfig& config, double damping_ratio,
                                            double r_min, double r_max) {
  AlgorithmSpec settle;
  settle.dt_ratio =
      consolidation_alpha(config.material.contact_damping_ratio, config.dimension, r_min, r_max);
  settle.damping_ratio_translation = damping_ratio;
  settle.damping_ratio_rotation = damping_ratio;
  settle.lock_rotation = config.algorithm.lock_rotation;
  return settle;
}

struct ConsolidationOutcome {
  int64_t steps = 0;
  int phase = 0;  ///< the phase it ended in (0 frictionless, 1 friction on)
  bool converged = false;
  double stress_error = 0.0;       ///< max |p − σ3|/σ3 over the walls, last check
  double unbalanced_ratio = 0.0;   ///< unbalanced-force ratio, last check
  ConsolidationProgress progress;  ///< the last check's report (wall-clock fields included)
  std::string stray_note;          ///< stray_particle_note of the start, for a failure's error
};

/// The wall-clock side of ConsolidationProgress: elapsed time, the step
/// budget's bound and the extrapolated time to a static state
/// (consolidation_progress.hpp says how). Reads the clock only; the
/// consolidation does not depend on it.
class ConsolidationClock {
 public:
  /// `phase0_end`: the check at which a frictionless phase not static ends
  /// (frictionless_phase_cut's), where its estimate stops.
  ConsolidationClock(const TestSpec& test, int64_t phase0_end)
      : test_(test), phase0_end_(phase0_end), start_(std::chrono::steady_clock::now()) {}

  ConsolidationProgress check(int phase, int64_t steps, double stress_error,
                              double unbalanced_ratio) {
    ConsolidationProgress p;
    p.phase = phase;
    p.steps = steps;
    p.max_steps = test_.consolidation_max_steps;
    p.stress_error = stress_error;
    p.unbalanced_ratio = unbalanced_ratio;
    p.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double per_step = steps > 0 ? p.elapsed_s / static_cast<double>(steps) : 0.0;
    p.remaining_max_s = static_cast<double>(std::max<int64_t>(0, p.max_steps - steps)) * per_step;
    // Distance to static in e-folds of the criterion furthest from its
    // tolerance (≤ 0: both met).
    const double d = std::max(std::log(stress_error / test_.consolidation_tolerance),
                              std::log(unbalanced_ratio / test_.consolidation_unbalanced));
    if (phase != phase_) window_.clear();
    phase_ = phase;
    window_.emplace_back(steps, d);
    if (window_.size() > kWindow) window_.pop_front();
    p.remaining_s = p.remaining_max_s;
    if (!(d > 0.0)) {
      p.steps_to_go = 0;
    } else if (window_.size() >= 3) {
      const auto& [steps0, d0] = window_.front();
      const double rate = (d0 - d) / static_cast<double>(steps - steps0);  // e-folds per step
      if (rate > 0.0 && std::isfinite(d0))
        p.steps_to_go =
            static_cast<int64_t>(std::ceil(std::min(d / rate, static_cast<double>(p.max_steps))));
      // the frictionless phase ends at its cut, static or not
      if (phase == 0 && p.steps_to_go > 0 && steps < phase0_end_)
        p.steps_to_go = std::min(p.steps_to_go, phase0_end_ - steps);
    }
    if (p.steps_to_go >= 0)
      p.remaining_s = std::min(p.remaining_max_s, static_cast<double>(p.steps_to_go) * per_step);
    return p;
  }

 private:
  static constexpr size_t kWindow = 10;  ///< checks the trend is taken over
  const TestSpec& test_;
  int64_t phase0_end_;
  std::chrono::steady_clock::time_point start_;
  int phase_ = -1;
  std::deque<std::pair<int64_t, double>> window_;
};

/// Runs the consolidation on `world` (its integration set from `settle`
/// by `integration_for`, which the critical-damping fallback calls again),
/// with `walls` walls of type `Side`, on options.threads threads (one
/// afterwards: its copies are the trials, which a calibration runs in
/// parallel), and calls options.progress after every check.
/// Only the blow-up checks (non-finite state, overlap beyond the limit)
/// stay on meanwhile: with light damping the energy checks read the walls'
/// work as energy made by the integrator — the kinetic energy a servo wall
/// pumps into a gas exceeds anything the springs have stored, and the
/// ledger's sampled damping and wall powers alias when velocities oscillate
/// at the contact frequency (a false "energy created" on the hexagonal
/// REVs). Consolidation must reach the static state demanded, which no
/// rattling or growing run does. Throws std::runtime_error when the kernel
/// diverges; the caller decides what non-convergence means.
template <class Side, int walls, class Sample>
ConsolidationOutcome run_consolidation(Sample& world, const TestSpec& test, double friction,
                                       AlgorithmSpec settle,
                                       Integration (*integration_for)(const Sample&,
                                                                      const AlgorithmSpec&),
                                       const ConsolidationOptions& options) {
  world.set_threads(options.threads);
  world.set_integration(integration_for(world, settle));
  const KernelOptions kernel_options = world.options();
  KernelOptions no_ledger = kernel_options;
  no_ledger.max_energy_created = std::numeric_limits<double>::infinity();
  no_ledger.max_energy_ratio = std::numeric_limits<double>::infinity();
  world.set_options(no_ledger);

  const double sigma3 = test.lateral_stress;
  constexpr int kCheckEvery = 200;
  const int64_t max_steps = test.consolidation_max_steps;
  // The critical-damping fallback comes after a quarter of the budget of
  // the undamped consolidation's step (α of consolidation_settings): where
  // contact dashpots shrank the step (consolidation_dashpot_factor), as
  // many more steps as it shrank, i.e. after the same simulated time. With
  // dashpots the light damping needs those steps (random_500_3d at ζ_c =
  // 0.3: 1 269 800 steps at the α 0.0303 of the factor before 2026-12-03,
  // 568 200 at today's 0.0725), and critical damping switched on
  // before the packing is static does not bring it there: its walls creep
  // (x walls out, y walls in, no servo reversal) with the wall stress error
  // near 0.2 % and the unbalanced-force ratio near 0.01 for the rest of a
  // 2·10⁶-step budget.
  //
  // The frictionless phase gets at most those first steps (the quarter),
  // and at most half the budget (frictionless_phase_cut: strong dashpots
  // put the quarter past the half, from S < 1/4 past the budget's end): a
  // phase 0 not static by then ends there, friction goes on with the light
  // damping, and critical damping comes at twice the quarter's step. A
  // frictionless packing at sigma3 can creep toward a denser state for far
  // longer than a frictional one takes to lock (a likely reason, not
  // measured: its overlaps there are ~1e-4 of the radius, near jamming,
  // where the softest collective modes may fall below the light damping's
  // ζ·ω_c and creep, over-damped). Measured: 5 000 spheres of
  // random_500_3d's gas held sigma3 within 0.5 % with an unbalanced-force
  // ratio of 0.005-0.02 from 150 000 to 560 000 steps, while friction
  // switched on at 150 000 locked it in 1 400 steps; 500 spheres in a
  // 100 000-step budget: no static state in it, frictionless, then 28 000
  // steps with the cut.
  const double shrink = consolidation_step_shrink(settle.dt_ratio);
  const int64_t critical_after = critical_damping_after(max_steps, shrink);
  const int64_t cut_after = frictionless_phase_cut(max_steps, shrink);
  int64_t switch_at = critical_after;  ///< critical damping from here (phase 1)
  ConsolidationOutcome out;
  {
    std::array<std::span<const double>, walls / 2> centres;
    centres[0] = world.x();
    centres[1] = world.y();
    if constexpr (walls == 6) centres[2] = world.z();
    out.stray_note = stray_particle_note(centres, world.radius());
  }
  // the check at which phase 0 is cut (the first at or after cut_after)
  ConsolidationClock clock(test, (cut_after + kCheckEvery - 1) / kCheckEvery * kCheckEvery);
  bool critical = false;
  for (out.phase = 0; out.phase < 2; ++out.phase) {
    world.set_particle_friction(out.phase == 0 ? 0.0 : friction);
    bool done = false;
    while (!done) {
      for (int k = 0; k < kCheckEvery; ++k) {
        for (int s = 0; s < walls; ++s) {
          const auto side = static_cast<Side>(s);
          world.wall(side).velocity = servo_velocity(world, side, sigma3, test.servo_gain);
        }
        if (!world.step(1))
          throw std::runtime_error(std::string("consolidation diverged: ") +
                                   to_string(world.divergence()) + out.stray_note);
      }
      out.steps += kCheckEvery;
      if (!critical && out.phase == 1 && out.steps >= switch_at) {
        critical = true;
        settle.damping_ratio_translation = settle.damping_ratio_rotation = 1.0;
        world.set_integration(integration_for(world, settle));
      }
      double err = 0.0;
      for (int s = 0; s < walls; ++s)
        err = std::max(err, std::abs(wall_pressure(world, static_cast<Side>(s)) - sigma3) / sigma3);
      out.stress_error = err;
      out.unbalanced_ratio = world.measure().unbalanced_force_ratio;
      out.progress = clock.check(out.phase, out.steps, out.stress_error, out.unbalanced_ratio);
      if (options.progress) options.progress(out.progress);
      done = err < test.consolidation_tolerance &&
             out.unbalanced_ratio < test.consolidation_unbalanced;
      if (out.steps >= max_steps) break;
      if (out.phase == 0 && !done && out.steps >= cut_after) {  // capped
        switch_at = 2 * critical_after;
        break;
      }
    }
    if (!done && !(out.phase == 0 && out.steps < max_steps)) break;
    out.converged = done && out.phase == 1;
  }
  if (out.phase > 1) out.phase = 1;
  world.set_options(kernel_options);
  world.set_threads(1);
  for (int s = 0; s < walls; ++s) world.wall(static_cast<Side>(s)).velocity = 0.0;
  return out;
}

/// What a consolidation that did not converge reached, for its error.
inline std::string consolidation_failure(const ConsolidationOutcome& o, const TestSpec& test) {
  const auto percent = [](double v) { return num(100.0 * v, 3) + " %"; };
  return "consolidation did not reach a static state in " +
         std::to_string(test.consolidation_max_steps) + " steps (" +
         (o.phase == 0 ? "frictionless phase" : "friction phase") + ", largest wall stress error " +
         percent(o.stress_error) + " of sigma3, tolerance " +
         percent(test.consolidation_tolerance) + "; unbalanced-force ratio " +
         std::to_string(o.unbalanced_ratio) + ", tolerance " +
         std::to_string(test.consolidation_unbalanced) + ")" +
         (o.stray_note.empty() ? "; raise test.consolidation_max_steps or loosen the tolerances"
                               : o.stray_note);
}

/// The consolidated state's account of `o` (started at `t0`); throws
/// std::runtime_error saying what was reached when it did not converge.
template <class State>
void finish_consolidation(State& state, const ConsolidationOutcome& o, const TestSpec& test,
                          std::chrono::steady_clock::time_point t0) {
  state.converged = o.converged;
  state.stress_error = o.stress_error;
  state.unbalanced_ratio = o.unbalanced_ratio;
  state.steps = o.steps;
  state.wall_time_s = seconds_since(t0);
  if (!state.converged) throw std::runtime_error(consolidation_failure(o, test));
}

/// The stable α of a consolidated sample (a probe copy; its stable-step
/// estimate of the contact network, which does not depend on Δt: any
/// valid step will do).
template <class Sample>
double stable_dt_ratio_of(Sample probe, const AlgorithmSpec& algorithm,
                          Integration (*integration_for)(const Sample&, const AlgorithmSpec&)) {
  AlgorithmSpec a = algorithm;
  a.dt_ratio = std::min(a.dt_ratio, 0.1);
  probe.set_integration(integration_for(probe, a));
  probe.update_forces();
  return probe.stability_estimate().dt_ratio_stable;
}

/// The loading's start, the same in 2D and 3D: the spec's integration on
/// `world`, the run's scales, planned steps and strain rate in `out`; the
/// wall `fixed` at rest, the `platen` moving in at the speed that reaches
/// test.vertical_strain of `h0` in Nstep steps.
template <class Sample, class Result, class Side>
void start_loading(Sample& world, Result& out, const AlgorithmSpec& algorithm, const TestSpec& test,
                   double h0, Integration (*integration_for)(const Sample&, const AlgorithmSpec&),
                   Side fixed, Side platen) {
  out.particles = world.size();
  out.integration = integration_for(world, algorithm);
  world.set_integration(out.integration);
  out.scales = world.reference_scales();
  const double dt = out.integration.dt;
  const int64_t nstep = algorithm.steps;
  out.steps_planned = nstep;
  out.strain_rate = test.vertical_strain / (static_cast<double>(nstep) * dt);
  world.wall(fixed).velocity = 0.0;
  world.wall(platen).velocity = -test.vertical_strain * h0 / (static_cast<double>(nstep) * dt);
}

/// A monitoring point's stresses, energies and ratios from the kernel's
/// measures (the fields MonitorPoint and TriaxialPoint share).
template <class Point, class Measures>
void copy_measures(Point& p, const Measures& ms) {
  p.b = ms.boundary_stress;
  p.sigma = ms.homogenized_stress;
  p.kinetic_energy = ms.kinetic_energy_translation + ms.kinetic_energy_rotation;
  p.kinetic_energy_rotation = ms.kinetic_energy_rotation;
  p.elastic_energy = ms.elastic_energy;
  p.unbalanced_force_ratio = ms.unbalanced_force_ratio;
  p.inertial_number = ms.inertial_number;
  p.coordination_number = ms.coordination_number;
}

/// The loading's monitoring loop, the same in 2D and 3D: out.steps_planned
/// steps (start_loading) in `m` equal stretches, a monitoring point of type
/// Point before the first and after each (its measures here, the rest by
/// complete(point)), pushed to out.series and passed to `monitor`, which
/// may stop the run. Each step: servo() sets the wall velocities, the
/// kernel steps once, track() follows the peak. Fills out's step count,
/// divergence and early stop; `start_steps`: the steps the world had taken
/// before the run, for the divergence step.
template <class Point, class Sample, class Result, class Complete, class Monitor, class Servo,
          class Track>
void run_monitored(Sample& world, Result& out, int m, int64_t start_steps, Complete complete,
                   const Monitor& monitor, Servo servo, Track track) {
  out.series.reserve(m + 1);
  auto record = [&](int64_t step) {
    Point p;
    p.step = step;
    copy_measures(p, world.measure(out.strain_rate));
    complete(p);
    out.series.push_back(p);
    return !monitor || monitor(p);
  };
  const int64_t nstep = out.steps_planned;
  bool keep_going = record(0);
  int64_t done = 0;
  for (int k = 1; k <= m && keep_going; ++k) {
    const int64_t target = nstep * k / m;
    while (done < target) {
      servo();
      if (!world.step(1)) break;
      ++done;
      track();
    }
    if (world.divergence() != Divergence::kNone) {
      out.diverged = true;
      out.divergence = world.divergence();
      out.divergence_step = world.divergence_step() - start_steps;
      break;
    }
    keep_going = record(done);
  }
  out.stopped_early = !out.diverged && !keep_going && done < nstep;
  out.steps_run = done;
}

}  // namespace demcal::detail
