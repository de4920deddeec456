// Export: the calibrated, upscaled parameters as an input deck for another
// DEM code (issue #6 §4). One deck per format:
//
//   lammps   — LAMMPS (checked with the Debian 12 build, 29 Sep 2021,
//              GRANULAR package): units si, dimension 2, discs
//              (set density/disc, fix nve/sphere disc), pair_style
//              gran/hooke/history kn kt 0 0 μ 0, global viscous damping on
//              translation per radius class (fix viscous ... scale), walls
//              as fix wall/gran and wall/gran/region on bands of particles
//              (the top wall a region moving at the loading speed, the
//              lateral walls regions moved by demcal's per-step servo law,
//              one flat formula each), run length Nstep. Every derived
//              quantity is computed by LAMMPS from the parameters block; the
//              run can be split (write_restart and an args file); the deck
//              writes its series (DeckFiles::series), which `demcal score`
//              reads (demcal/scoring/external_series.hpp).
//   liggghts — LIGGGHTS-PUBLIC 3.x (checked with 3.8): gran model
//              hooke/stiffness with absolute damping off, per-atom-type-pair
//              kn/kt, mesh walls with a servo (fix
//              mesh/surface/stress/servo, gain from demcal's servo law) on
//              the lateral walls.
//
// Both formats run at α·f·Δt_crit for Nstep/f steps, f =
// dashpot_step_factor(ζ_t) (kernel/particle_scales.hpp): their fix viscous is explicit.
// Every mapping, and every place where the other code cannot do exactly
// what demcal does, is written as comments into the deck itself.
#pragma once

#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "demcal/kernel/particle_scales.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/upscaling/upscaling.hpp"

namespace demcal {

/// The files of a deck, every one named after the deck's whole file name
/// DECK (NAME.lammps, NAME.liggghts), so that decks of both formats, or two
/// of one format under two names, share no file in one folder (README,
/// "Export"). The one home of these names: the decks, export, verify and
/// the tests take them from here.
struct DeckFiles {
  std::string data;          ///< DECK.data: the particles it reads
  std::string series;        ///< DECK.series.csv: the monitoring series it writes
  std::string restart;       ///< DECK.restart: a split run's restart (2D LAMMPS deck)
  std::string restart_args;  ///< DECK.restart.args: the continuation's arguments
  std::string deck;          ///< DECK itself
  /// DECK-WALL.stl: a LIGGGHTS deck's wall mesh (WALL top, left, xmin, ...).
  std::string mesh(const std::string& wall) const { return deck + "-" + wall + ".stl"; }
};
DeckFiles deck_files(const std::string& deck);

struct ExportOptions {
  std::string format = "lammps";  ///< lammps | liggghts
  /// The deck's file name: the files it reads (written next to it) and
  /// writes are named after it (deck_files).
  std::string deck_name = "prototype";
  /// Radius classes (atom types) for the per-type translational damping;
  /// a monodisperse assembly gets one.
  int max_types = 8;
  std::string provenance;  ///< one line: where the parameters came from
  /// Set: the parameters are not certified (a failed calibration's, used
  /// with --allow-failed), and why when known (else empty); the deck's
  /// header says so.
  std::optional<std::string> uncertified;
  /// LAMMPS only: the deck consolidates the prototype itself (a first stage
  /// bringing it to isotropic sigma3 with demcal's servo, damping, friction
  /// phases and static criterion; scene/biaxial.cpp), then loads it. The
  /// assembly is then the prototype as generated.
  bool consolidate_in_deck = false;
};

struct ExportResult {
  std::string deck;  ///< the input script
  /// Other files the deck reads, by name (the data file, meshes).
  std::map<std::string, std::string> files;
  /// The timestep written into the deck [s]: α·f·Δt_crit, f =
  /// dashpot_step_factor(ζ_t) (the engines' fix viscous is
  /// explicit; demcal's damping is not).
  double dt = 0.0;
  int64_t steps = 0;         ///< the run length written into the deck: Nstep/f (same loading time)
  double step_factor = 1.0;  ///< f = sqrt(1 + ζ_t²) − ζ_t
  int types = 0;             ///< radius classes
  /// Largest relative error of the per-type damping against demcal's
  /// per-particle D_t = ζ_t·2·sqrt(kn·m_i).
  double damping_class_error = 0.0;
  std::vector<std::string> notes;  ///< what could not be mapped exactly
};

/// The deck for running `params` (the prototype's: Nstep upscaled) on
/// `assembly` (best a consolidated state: its walls are the starting wall
/// positions) with the config's material and test. Throws InputError for
/// an unknown format.
ExportResult export_deck(const SceneConfig& config, const AlgorithmSpec& params,
                         const Assembly& assembly, const ExportOptions& options);

/// The run length a deck of `params` writes, 2D and 3D, either format
/// (ExportResult::steps): Nstep/f rounded, at least 1, f =
/// dashpot_step_factor(ζ_t) (the engines' fix viscous is explicit): the
/// same loading time as demcal's Nstep. It depends on no particle: `demcal
/// verify --engine lammps` estimates the deck's run from it before any
/// deck is written.
int64_t deck_steps(const AlgorithmSpec& params);

/// Radius classes: type (1-based) of every particle, at most `max_types`
/// classes of (nearly) equal counts; equal radii share a class.
std::vector<int> radius_classes(const std::vector<double>& radii, int max_types, int* types);

}  // namespace demcal
