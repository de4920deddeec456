// params.json, the answer of `demcal calibrate`: its schema in one place.
// It lives in the upscaling layer because it carries the prototype block
// (the REV's parameters upscaled). Deterministic: the same config and seed
// give the same bytes, whatever --jobs or --resume.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/search/calibration.hpp"
#include "demcal/search/evidence.hpp"

namespace demcal {

/// Particle-steps actually run by the trials (early stops counted as run):
/// a deterministic measure of a calibration's cost.
double particle_steps_run(const std::vector<TrialRecord>& trials, int64_t particles);

/// params.json (schema demcal.params/1) of a calibration of `config` on the
/// consolidated REV `state` with `options`: the REV block, the prototype
/// block and the upscaling law, the criteria of the best trial, the
/// certificate, and what reproduces it (config, seed, hash, version).
nlohmann::json params_file(const SceneConfig& config, const ConsolidatedState& state,
                           const CalibrationOptions& options, const CalibrationSummary& summary);
/// The same for a triaxial (3D) calibration on the consolidated spheres
/// `state`: "dimension": 3, the REV block from the sphere scales, the
/// prototype block for the spheres the config's "prototype" names (the REV
/// itself without one), Nstep by default_law(3).
nlohmann::json params_file(const SceneConfig& config, const TriaxialState& state,
                           const CalibrationOptions& options, const CalibrationSummary& summary);
/// The schema params_file() writes and read_params_file() accepts.
inline constexpr const char* kParamsSchema = "demcal.params/1";
/// A params.json read back and checked like a config: valid JSON without
/// duplicate keys, this schema, a version string, and a `rev` block whose
/// numbers are finite and in range (rev_params_from_json), a prototype
/// particle count that fits, a "dimension" of 2 or 3 when present (absent:
/// 2). Every key is one demcal writes, of the type it writes (unknown keys
/// are refused, at the top and in rev, prototype and upscaling), and the
/// two every params.json demcal has written holds are required: "success"
/// (true or false) and "dt_ratio_stable" (a number > 0). Every fault is an
/// InputError naming the file and the key (exit 2).
nlohmann::json read_params_file(const std::string& path);
/// Also refused: a "rev" of null (a calibration in which no trial passed
/// writes no parameters), and a rev.dt_ratio beyond the "dt_ratio_stable"
/// recorded beside it (require_stable_dt_ratio, the rule of `demcal run`).
/// The same checks on a params.json's text (`path` names it in errors);
/// read_params_file reads the file and calls this.
nlohmann::json parse_params_text(std::string_view text, const std::string& path);
/// A params.json's "success": an InputError naming `path` and the field
/// when it is missing or not true or false (a "false" string is not false).
bool calibration_succeeded(const nlohmann::json& params, const std::string& path);
/// What `upscale`, `verify` and `export` ask of a params.json before using
/// it (unless --allow-failed): a calibration that succeeded. "success":
/// false is an InputError naming `path` and the field success, with the
/// calibration's message and the remedy; so is a "success" missing or not
/// true or false (calibration_succeeded).
void require_calibrated(const nlohmann::json& params, const std::string& path);
/// A params.json whose calibration failed ("success": false), used anyway
/// (--allow-failed): why its parameters are not certified, its "message"
/// (empty when it has none); nothing for a calibration that succeeded. What
/// a deck's header says of them (ExportOptions::uncertified), for
/// `demcal export` and the deck `demcal verify --engine lammps` runs alike.
std::optional<std::string> uncertified_reason(const nlohmann::json& params);
/// The dimension a params.json was calibrated in: its "dimension" (2 when
/// absent, as 2D params.json files have always been written).
int params_dimension(const nlohmann::json& params);

/// The accuracy evidence of `demcal calibrate --evidence`: the converged
/// reference (Nstep ×8 and ×16, Richardson) and the paper-recipe baseline.
struct CalibrationEvidence {
  ReferenceEvidence reference;
  BaselineResult baseline;
  int64_t baseline_start_steps = 0;
};
/// A trial's peak error against the reference, (P_ref − P)/|P_ref|, or null
/// for a run without a valid peak (stopped, diverged).
nlohmann::json peak_error_json(const TrialRecord& trial, double reference_peak);
/// The `evidence` block of params.json; `best` is the calibrated trial.
nlohmann::json evidence_block(const CalibrationEvidence& evidence, const TrialRecord& best);
/// evidence.jsonl: the reference runs, then the baseline trials, one
/// to_json(TrialRecord) with its peak_error per line.
std::string evidence_lines(const CalibrationEvidence& evidence);

}  // namespace demcal
