// The calibration report: DIR/report.html, self-contained
// (inline SVG and CSS, nothing fetched, opens offline), and DIR/report.md,
// the same facts in text.
//
// Contents, the answer first: the parameter table (multipliers and absolute
// values, REV and prototype), the criteria reached against their
// tolerances, the convergence certificate and the command that reproduces
// the run; then the paper's panels for the start point and the calibrated
// run (b_yy and σ_yy, σxy and σyx, the lateral components b_xx and σ_xx,
// the servo error, all against the vertical strain), the diagnosis in words
// (start point and rejected neighbours of the result), the search history,
// speed against accuracy (every trial's cost against its force-balance
// error and, with the evidence runs, its peak error against a converged
// reference; Pareto front, chosen point and paper-recipe baseline marked),
// the upscaling line, and the assembly at the peak (disks coloured by
// rotation, contact forces as lines of width ∝ force).
//
// 3D (spheres, triaxial test, dimension = 3): the same report from the same
// sections; the panels are the axial b_zz and σ_zz, each lateral component
// (xx, yy), the three shear pairs (σ_xy/σ_yx, σ_xz/σ_zx, σ_yz/σ_zy: moment
// balance) and the servo error of each of the four lateral walls; the
// assembly is a shaded isometric view of the spheres coloured by their
// contact force (sphere_svg.hpp), with final.vtk beside it for ParaView.
//
// Plots are rendered by gnuplot (`set terminal svg`) in a private temporary
// folder, with no shell and no user text in the scripts; without gnuplot the
// report carries every number and says how to get the plots. The assembly
// picture is drawn directly as SVG and needs nothing.
//
// The report renders facts; it runs nothing itself. The runs it shows
// besides the search's trials come from search/evidence.hpp. Inside
// src/report: facts.cpp gathers what the sections share (ReportFacts),
// sections_*.cpp write one section each to both documents (doc.cpp),
// plots.cpp plans and renders the gnuplot figures (gnuplot.cpp runs it),
// assembly_svg.cpp draws the assembly and html.cpp holds the page and CSS.
#pragma once

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scoring/scoring.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/search/evidence.hpp"

namespace demcal {

struct ReportInput {
  std::string scene;
  std::string command;    ///< the command line that reproduces the run
  nlohmann::json params;  ///< params.json as written (rev/prototype blocks)
  CalibrationSummary summary;
  Tolerances tolerances;
  double accuracy = 0.02;
  double lateral_stress = 0.0;  ///< σ3 [Pa]
  double dt_ratio_max = 0.0;    ///< the search's upper bound on α (0: unknown)
  int64_t particles = 0;        ///< REV
  int64_t prototype_particles = 0;
  std::optional<double> analytical_peak;  ///< b_yy, rotation locked (hexagonal scenes)
  std::optional<ReportRun> start, best;
  std::optional<AssemblyPicture> picture;  ///< the calibrated run at its peak
  std::optional<BaselineResult> baseline;
  std::optional<ReferenceEvidence> reference;

  // 3D (spheres, triaxial test): the runs in place of start/best/picture.
  int dimension = 2;
  std::optional<ReportRun3D> start3, best3;
  std::optional<SpherePicture> sphere_picture;  ///< the calibrated run at its peak
  std::string vtk_file;  ///< the picture's world as VTK beside the report ("" none)
};

/// The runs of rerun_start_and_result() (search/evidence.hpp) into `input`.
void attach_runs(ReportInput& input, ResultRuns runs);
/// The same for a 3D scene (sets input.dimension = 3; runs.world is not kept).
void attach_runs(ReportInput& input, ResultRuns3D runs);

struct ReportOptions {
  /// The gnuplot program (a name looked up on PATH, or a path); "" renders
  /// no plots.
  std::string gnuplot = "gnuplot";
  int near_failures = 6;  ///< rejected neighbours of the result described
};

struct Report {
  std::string html, markdown;
  bool plots = false;       ///< every gnuplot figure was rendered
  std::string plot_status;  ///< what happened to the plots, in words
};

/// Deterministic for given input and gnuplot version.
Report make_report(const ReportInput& input, const ReportOptions& options = {});

/// A program on PATH (or a path with '/'), "" when not found/executable.
std::string find_program(const std::string& name);

/// Run gnuplot on `script` in a fresh private temporary folder that holds
/// `files` (name → content; plain names, no '/'); return the content of each
/// name in `outputs` the script wrote. No shell is involved; HOME points at
/// the temporary folder (no user init file) and LC_ALL=C.UTF-8 (decimal points, UTF-8 labels).
/// `error` receives gnuplot's complaint when it fails.
std::map<std::string, std::string> run_gnuplot(const std::string& program,
                                               const std::string& script,
                                               const std::map<std::string, std::string>& files,
                                               const std::vector<std::string>& outputs,
                                               std::string* error = nullptr);

}  // namespace demcal
