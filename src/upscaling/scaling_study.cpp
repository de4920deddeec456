#include "demcal/upscaling/scaling_study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "demcal/io/files.hpp"
#include "demcal/io/format.hpp"
#include "demcal/io/json_integer.hpp"
#include "demcal/scene/consolidation_cache.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/run_output.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/search/trial_runner.hpp"
#include "demcal/upscaling/rev.hpp"

namespace demcal {

namespace fs = std::filesystem;
using nlohmann::json;

std::vector<int64_t> parse_sizes(const std::string& text, const std::string& option) {
  std::vector<int64_t> sizes;
  std::stringstream s(text);
  for (std::string f; std::getline(s, f, ',');) {
    char* end = nullptr;
    const long long v = std::strtoll(f.c_str(), &end, 10);
    if (f.empty() || *end != '\0' || v < 4 || v > 10000000)
      throw InputError(option, "",
                       "expected particle counts >= 4 separated by commas, got \"" + text + "\"");
    sizes.push_back(v);
  }
  std::sort(sizes.begin(), sizes.end());
  const auto twice = std::adjacent_find(sizes.begin(), sizes.end());
  if (twice != sizes.end())
    throw InputError(
        option, "",
        "size " + std::to_string(*twice) + " given twice in \"" + text + "\": each size once");
  if (sizes.size() < 2) throw InputError(option, "", "needs at least two sizes");
  return sizes;
}

json to_json(const ScalingSize& r) {
  json j{{"requested", r.requested}, {"particles", r.particles}, {"calibrated", r.calibrated}};
  add_consolidation_flat(j, r.consolidation);
  if (r.calibrated)
    j.update({{"success", r.success},
              {"best", to_json(r.best)},
              {"steps_per_particle", static_cast<double>(r.best.steps) / r.particles},
              {"richardson_error", r.richardson},
              {"peak_stress_yy", r.peak},
              {"trials", r.trials},
              {"wall_time_s", r.wall_time_s}});
  if (!r.fixed.trials.empty()) {
    json runs = json::array();
    for (const auto& t : r.fixed.trials) runs.push_back(to_json(t));
    j["fixed_multipliers"] = {{"found", r.fixed.found},
                              {"steps", r.fixed.steps},
                              {"best", r.fixed.found ? to_json(r.fixed.best) : json()},
                              {"runs", runs},
                              {"wall_time_s", r.fixed.wall_time_s}};
  }
  return j;
}

ScalingSize scaling_size_from_json(const json& j, const std::string& source) {
  // A count the file holds: a whole number in [min, max], or an InputError
  // naming the file and the key (never a cast of 5e110 to an integer).
  constexpr int64_t kAny = std::numeric_limits<int64_t>::max();
  const auto count = [&source](const json& block, const std::string& key, int64_t min, int64_t max,
                               const std::string& where = "") {
    return json_integer(block.at(key), min, max, source, where + key);
  };
  try {
    ScalingSize r;
    r.requested = count(j, "requested", 1, kMaxParticles);
    r.particles = count(j, "particles", 1, kMaxParticles);
    r.calibrated = j.at("calibrated").get<bool>();
    r.consolidation = consolidation_flat_from_json(j, source);
    if (r.calibrated) {
      r.success = j.at("success").get<bool>();
      r.best = algorithm_from_json(j.at("best"), source, "best");
      r.richardson = j.at("richardson_error").get<double>();
      r.peak = j.at("peak_stress_yy").get<double>();
      r.trials = static_cast<int>(count(j, "trials", 0, std::numeric_limits<int>::max()));
      r.wall_time_s = j.at("wall_time_s").get<double>();
    }
    if (j.contains("fixed_multipliers")) {
      const json& f = j.at("fixed_multipliers");
      r.fixed.found = f.at("found").get<bool>();
      r.fixed.steps = count(f, "steps", 0, kAny, "fixed_multipliers.");
      r.fixed.wall_time_s = f.value("wall_time_s", 0.0);
      if (r.fixed.found)
        r.fixed.best = trial_from_json(f.at("best"), source + ": fixed_multipliers.best");
      for (const auto& t : f.at("runs"))
        r.fixed.trials.push_back(trial_from_json(t, source + ": fixed_multipliers.runs"));
    }
    return r;
  } catch (const json::exception& e) {
    throw InputError(source, "", std::string("not a demcal scaling result: ") + e.what());
  }
}

bool law_holds(double measured_exponent, const ScalingLaw& law) {
  return std::abs(measured_exponent - law.exponent) <= 0.1;
}

std::string law_words(const ScalingLaw& law) {
  return law.name() == "linear" ? "linear" : "N^" + num(law.exponent, 3);
}

Spread spread_of(const std::vector<double>& v) {
  Spread s;
  if (v.empty()) return s;
  s.min = *std::min_element(v.begin(), v.end());
  s.max = *std::max_element(v.begin(), v.end());
  for (double x : v) s.mean += x;
  s.mean /= static_cast<double>(v.size());
  s.relative = s.mean > 0 ? (s.max - s.min) / s.mean : 0.0;
  return s;
}

FamilyFile scaling_family_file(const SceneConfig& config) {
  if (config.assembly.type != "file" || config.dimension == 3) return {};
  if (config.prototype.file.empty()) return {"assembly.file", config.assembly.file};
  return {"prototype.file", config.prototype.file};
}

namespace {

json read_json(const std::string& path) {
  std::ifstream in(path);
  try {
    return json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(path, "", std::string("not JSON: ") + e.what());
  }
}

bool stop_asked(const ScalingStudyOptions& o) { return o.stop && o.stop->load(); }

/// Thrown where a stop (options.stop) cuts a step of the study short: in a
/// consolidation (from its progress callback, the one hook it offers), a
/// step search or the forward reference. run_scaling_study() catches it and
/// returns the study interrupted; the step cut writes nothing.
struct StudyStopped {};

void throw_if_stopped(const ScalingStudyOptions& o) {
  if (stop_asked(o)) throw StudyStopped{};
}

/// One size's consolidated sample, disks or spheres, and the runner the
/// search and the step search see it through (addresses stable: held by
/// pointer).
struct SizeState {
  SceneConfig scene;
  std::optional<ConsolidatedState> disks;
  std::optional<TriaxialState> spheres;
  std::unique_ptr<TrialRunner> runner;
  int64_t particles = 0;
  ConsolidationRecord consolidation;
};

/// Size n of the study, as its assembly's errors name it
/// (make_assembly's `which`: "... for size 40's assembly").
std::string size_label(int64_t n) { return "size " + std::to_string(n); }

}  // namespace

/// The family of scenes and their consolidated states, 2D or 3D. A 2D size
/// that is not calibrated writes its consolidated packing to the work
/// folder (size-N/consolidated.csv, an output); a resumed study
/// consolidates every size again from its generated or cut assembly: the
/// consolidation cache's exact state, or with the cache off the whole
/// consolidation again (deterministic; the largest size's is the cost).
/// Each size's assembly is made once: check_scaling_sizes() makes (a file
/// family: cuts, counts) and checks them, state() consolidates them.
class ScalingFamily {
 public:
  ScalingFamily(const SceneConfig& config, const ScalingStudyOptions& o)
      : config_(config), o_(&o), sizes_(o.sizes), calibrate_max_(o.calibrate_max) {
    from_file_ = config.assembly.type == "file";
    if (!from_file_) return;
    if (config.dimension == 3)
      throw InputError(config.source, "assembly.type",
                       "a 3D scaling study needs a generated family (fcc or random): REVs cut "
                       "from a sphere file are `demcal rev`'s");
    const FamilyFile family = scaling_family_file(config);
    require_config_file(config, family.key, family.path);
    file_prototype_ = read_particle_file(family.path);
    if (file_prototype_.size() < o.sizes.back())
      throw InputError(
          "--sizes", "",
          "the prototype file has only " + std::to_string(file_prototype_.size()) + " particles");
  }
  /// The options the study runs with (the work folder, stop, logs): those
  /// it was checked with but for these; other sizes or another
  /// calibrate_max than the checked ones are a caller's error.
  void run_with(const ScalingStudyOptions& o) {
    if (o.sizes != sizes_ || o.calibrate_max != calibrate_max_)
      throw std::invalid_argument(
          "run_scaling_study: the options' sizes or calibrate_max are not the checked ones");
    o_ = &o;
  }
  const SceneConfig& config() const { return config_; }
  bool from_file() const { return from_file_; }
  int64_t file_particles() const { return file_prototype_.size(); }
  /// The particles size n makes (the generator's rounded count, or the
  /// REV cut from the file, kept for the check and the run), without
  /// consolidating: what the study's sizes are checked on before any work.
  int64_t made_count(int64_t n) {
    if (!from_file_) return particles_of_size(config_, n);
    auto it = disks_.find(n);
    if (it == disks_.end()) it = disks_.emplace(n, cut_rev(file_prototype_, n)).first;
    return it->second.size();
  }
  /// Why a size can make another count than it asks, for an error (""
  /// when it makes the count asked).
  std::string rounding() const {
    return from_file_
               ? "REVs cut from " + scaling_family_file(config_).path + " take whole particles"
               : size_rounding(config_);
  }
  SceneConfig scene(int64_t n) const { return from_file_ ? config_ : scene_of_size(config_, n); }
  /// Every size's assembly made and checked as a scene's is before it is
  /// consolidated (make_assembly, make_sphere_assembly: the derived scales
  /// and the overlap at sigma3), its errors naming the size; an REV cut
  /// from the file (made_count's) keeps the file's positions and radii:
  /// check_assembly, naming the file. None consolidated: a size the
  /// study cannot run is refused before any folder is made, not when the
  /// study comes to it (after the smaller sizes' calibrations).
  void check_assemblies() {
    for (int64_t n : sizes_) {
      if (config_.dimension == 3)
        spheres_.emplace(n, make_sphere_assembly(scene(n), size_label(n)));
      else if (!from_file_)
        disks_.emplace(n, make_assembly(scene(n), size_label(n)));
      else
        check_assembly(config_, disks_.at(n), size_label(n), scaling_family_file(config_).path);
    }
  }

  const SizeState& state(int64_t n) {
    auto it = states_.find(n);
    if (it != states_.end()) return *it->second;
    auto st = std::make_unique<SizeState>();
    st->scene = scene(n);
    // A stop ends the consolidation at its next check (every 200 steps);
    // the caller's progress callback sees every check.
    ConsolidationOptions consolidation;
    if (o_->stop || o_->consolidation_progress)
      consolidation.progress = [this](const ConsolidationProgress& p) {
        throw_if_stopped(*o_);
        if (o_->consolidation_progress) o_->consolidation_progress(p);
      };
    // consolidate() and consolidate_triaxial() through the cache, "consolidating"
    // said only when it consolidates (not before a cache read).
    const std::string cache = consolidation_cache_dir();
    if (config_.dimension == 3) {
      const SphereAssembly a = take(spheres_, n);
      st->spheres.emplace(consolidate_cached<TriaxialState>(cache, st->scene, a, [&] {
        log("consolidating " + std::to_string(a.size()) + " spheres (size " + std::to_string(n) +
            ")");
        return consolidate_triaxial(st->scene, a, std::string(), consolidation);
      }));
      st->runner = std::make_unique<TriaxialRunner>(st->scene, *st->spheres);
      st->consolidation = consolidation_record(*st->spheres);
    } else {
      // A resumed study consolidates the same assembly again: the
      // consolidation cache (DEMCAL_CACHE_DIR) returns the exact state, or
      // the consolidation is redone, deterministic. (Settling the sample
      // again from its consolidated.csv, as until 2026-12-04, gave a
      // slightly different sample: criteria ~1e-7 away from an
      // uninterrupted study's.) consolidated.csv stays an output: the
      // forward size's sample, e.g. a prototype for `demcal verify`.
      const Assembly a = take(disks_, n);
      st->disks.emplace(consolidate_cached<ConsolidatedState>(cache, st->scene, a, [&] {
        log("consolidating " + std::to_string(a.size()) + " particles (size " + std::to_string(n) +
            ")");
        return consolidate(st->scene, a, std::string(), consolidation);
      }));
      st->runner = std::make_unique<BiaxialRunner>(st->scene, *st->disks);
      st->consolidation = consolidation_record(*st->disks);
      if (n > calibrate_max_) {
        make_output_dir(dir(n));
        write_file_atomic(dir(n) + "/consolidated.csv",
                          particle_csv(assembly_of(st->disks->world)));
      }
    }
    st->particles = st->runner->particles();
    // A cache read's time is the reading's: said so, as the commands say it
    // (print_consolidation_time, calibrate/), on a line that names the size
    // (no "consolidating" line came before it).
    log((st->consolidation.from_cache ? "size " + std::to_string(n) + ": " : std::string("  ")) +
        "consolidated in " + std::to_string(st->consolidation.steps) + " steps, " +
        (st->consolidation.from_cache ? "read from the cache in " : "") +
        num(st->consolidation.wall_time_s, 3) + " s");
    return *states_.emplace(n, std::move(st)).first->second;
  }
  /// Calibrate size n with the search of its dimension.
  CalibrationSummary calibrate_size(int64_t n, const CalibrationOptions& co) {
    const SizeState& st = state(n);
    return st.spheres ? calibrate(st.scene, *st.spheres, co) : calibrate(st.scene, *st.disks, co);
  }
  std::string dir(int64_t n) const { return o_->work_dir + "/size-" + std::to_string(n); }
  void log(const std::string& line) const {
    if (o_->log) o_->log(line);
  }

 private:
  /// Size n's checked assembly (check_assemblies()), handed to state() once.
  template <class A>
  static A take(std::map<int64_t, A>& assemblies, int64_t n) {
    auto node = assemblies.extract(n);
    if (node.empty())
      throw std::logic_error("scaling study: size " + std::to_string(n) + " was not checked");
    return std::move(node.mapped());
  }

  const SceneConfig config_;
  const ScalingStudyOptions* o_;
  const std::vector<int64_t> sizes_;
  const int64_t calibrate_max_;
  bool from_file_ = false;
  Assembly file_prototype_;
  /// Each size's assembly: a file family's cut (made_count), a generated
  /// family's made and checked (check_assemblies).
  std::map<int64_t, Assembly> disks_;
  std::map<int64_t, SphereAssembly> spheres_;
  std::map<int64_t, std::unique_ptr<SizeState>> states_;
};

namespace {

/// Step 1: calibrate a size (or reuse its result.json); nothing when a stop
/// cut the calibration (its finished trials stay in the size's trials.jsonl).
std::optional<ScalingSize> calibrate_size(ScalingFamily& family,
                                          const CalibrationOptions& calibration,
                                          const ScalingStudyOptions& o, int64_t n) {
  const std::string result_path = family.dir(n) + "/result.json";
  if (o.resume && fs::exists(result_path)) {
    ScalingSize r = scaling_size_from_json(read_json(result_path), result_path);
    family.log("size " + std::to_string(n) + ": reusing " + result_path);
    return r;
  }
  make_output_dir(family.dir(n));
  const SizeState& state = family.state(n);
  ScalingSize r;
  r.requested = n;
  r.particles = state.particles;
  r.consolidation = state.consolidation;
  CalibrationOptions co = calibration;
  co.jobs = o.jobs;
  co.trials_path = family.dir(n) + "/trials.jsonl";
  // A size stopped in its calibration (a signal, a kill) left its finished
  // trials: a resumed study continues from them (a resume matched the
  // study's settings and build, and a fresh start cleared the sizes).
  co.resume = o.resume && fs::exists(co.trials_path);
  if (!co.resume) fs::remove(co.trials_path);
  co.stop = o.stop;
  if (o.log)
    co.progress = [n, &o](const std::string& line) {
      o.log("size " + std::to_string(n) + ": " + line);
    };
  const CalibrationSummary s = family.calibrate_size(n, co);
  if (s.interrupted) return std::nullopt;
  r.calibrated = true;
  r.success = s.success;
  r.best = s.best;
  r.richardson = s.certificate.richardson_error;
  r.peak = s.certificate.peak;
  r.trials = static_cast<int>(s.trials.size());
  r.wall_time_s = s.wall_time_s;
  write_file_atomic(result_path, to_json(r).dump(2) + "\n");
  family.log("size " + std::to_string(n) + ": " + (s.success ? "calibrated" : "FAILED") +
             ", steps " + std::to_string(s.best.steps) + ", alpha " + num(s.best.dt_ratio) +
             ", zeta_t " + num(s.best.damping_ratio_translation) + ", zeta_r " +
             num(s.best.damping_ratio_rotation) + " (" + num(s.wall_time_s, 3) + " s)");
  return r;
}

/// Step 2: the smallest passing Nstep at the REV's multipliers at size n,
/// from the prediction of `law` (the candidate; or reuse fixed.json). Each
/// finished run goes to size-N/steps_search.jsonl (rewritten whole) and to
/// the log as it ends. A stop during it throws StudyStopped: no fixed.json;
/// a resumed search takes the finished runs from steps_search.jsonl and runs
/// from the first one it does not find there.
void fixed_multipliers(ScalingFamily& family, const ScalingStudyOptions& o, const ScalingSize& ref,
                       const ScalingLaw& law, const Tolerances& tolerances, int64_t n,
                       ScalingSize& r) {
  const std::string fixed_path = family.dir(n) + "/fixed.json";
  if (o.resume && fs::exists(fixed_path)) {
    const ScalingSize stored = scaling_size_from_json(read_json(fixed_path), fixed_path);
    r.particles = stored.particles;
    if (!r.calibrated) r.consolidation = stored.consolidation;
    r.fixed = stored.fixed;
    family.log("size " + std::to_string(n) + ": reusing " + fixed_path);
    return;
  }
  make_output_dir(family.dir(n));
  const SizeState& state = family.state(n);
  r.particles = state.particles;
  // A size beyond the calibrated ones records the consolidation this step
  // made or read (a calibrated size keeps its calibration's).
  if (!r.calibrated) r.consolidation = state.consolidation;
  const AlgorithmSpec start = upscale(ref.best, ref.particles, r.particles, law);
  family.log("size " + std::to_string(r.particles) +
             ": smallest passing Nstep at the REV's multipliers, from the " + law_words(law) +
             " prediction " + std::to_string(start.steps) + " (" +
             num(static_cast<double>(start.steps) * r.particles, 3) + " particle-steps)");
  const std::string runs_path = family.dir(n) + "/steps_search.jsonl";
  StepSearchRecord record;
  if (o.resume && fs::exists(runs_path))
    record.earlier = read_trials_text(read_text_file(runs_path), runs_path);
  else
    fs::remove(runs_path);
  record.on_trial = [&](const std::vector<TrialRecord>& trials, bool reused) {
    std::string text;
    for (const TrialRecord& t : trials) text += to_json(t).dump() + "\n";
    write_file_atomic(runs_path, text);
    const TrialRecord& t = trials.back();
    family.log("  " + std::to_string(t.params.steps) +
               " steps: " + (t.score.passed ? "pass" : "fail") + " (worst " +
               num(t.score.worst_excess, 3) + "x tol), " + num(t.wall_time_s, 3) + " s" +
               (reused ? " (finished before the stop, reused)" : ""));
  };
  const auto t0 = std::chrono::steady_clock::now();
  const StepSearch search =
      smallest_passing_steps(*state.runner, start, tolerances, o.stop, 8, record);
  if (search.interrupted) throw StudyStopped{};
  r.fixed.found = search.found;
  r.fixed.steps = search.found ? search.best.params.steps : 0;
  r.fixed.best = search.best;
  r.fixed.trials = search.trials;
  r.fixed.wall_time_s = seconds_since(t0);
  write_file_atomic(fixed_path, to_json(r).dump(2) + "\n");
}

/// Step 3: the fits and the law they measure.
void fit_laws(ScalingStudy& st) {
  std::vector<double> n_cal, steps_cal, n_fix, steps_fix, n_rep, steps_rep;
  std::vector<double> alphas, zetas_t, zetas_r;
  for (int64_t n : st.calibrated_sizes) {
    const ScalingSize& r = st.results[n];
    if (!r.success) continue;
    n_cal.push_back(static_cast<double>(r.particles));
    steps_cal.push_back(static_cast<double>(r.best.steps));
    alphas.push_back(r.best.dt_ratio);
    zetas_t.push_back(r.best.damping_ratio_translation);
    zetas_r.push_back(r.best.damping_ratio_rotation);
  }
  // Nstep at fixed multipliers over all sizes and over the REV and larger
  // (the representative sizes: the law is carried upward from the REV).
  for (int64_t n : st.sizes) {
    const ScalingSize& r = st.results[n];
    if (!r.fixed.found) continue;
    n_fix.push_back(static_cast<double>(r.particles));
    steps_fix.push_back(static_cast<double>(r.fixed.steps));
    if (n >= st.ref_size) {
      n_rep.push_back(static_cast<double>(r.particles));
      steps_rep.push_back(static_cast<double>(r.fixed.steps));
    }
  }
  st.lin_cal = fit_linear(n_cal, steps_cal), st.pow_cal = fit_power(n_cal, steps_cal);
  st.lin_fix = fit_linear(n_fix, steps_fix), st.pow_fix = fit_power(n_fix, steps_fix);
  st.lin_rep = fit_linear(n_rep, steps_rep), st.pow_rep = fit_power(n_rep, steps_rep);
  st.n_cal = n_cal.size(), st.n_fix = n_fix.size(), st.n_rep = n_rep.size();
  st.measured.exponent = n_rep.size() >= 2 ? st.pow_rep.slope : 1.0;
  st.measured.source = "demcal scaling " + st.scene + ": smallest passing Nstep at the " +
                       std::to_string(st.results[st.ref_size].particles) +
                       "-particle REV's multipliers, sizes >= REV";
  st.linear_holds = law_holds(st.measured.exponent, ScalingLaw{});
  st.alpha = spread_of(alphas), st.zeta_t = spread_of(zetas_t), st.zeta_r = spread_of(zetas_r);
}

/// Step 4: the forward check at the largest size, the candidate law's run
/// (the first of its search) against a reference with twice its steps. A
/// stop during the reference throws StudyStopped: no reference.json.
void forward_check(ScalingFamily& family, const ScalingStudyOptions& o, ScalingStudy& st,
                   const TrialRecord& law_run) {
  st.have_forward = true;
  st.law_run = law_run;
  const std::string ref_path = family.dir(st.forward_size) + "/reference.json";
  AlgorithmSpec ref_params = law_run.params;
  ref_params.steps = 2 * law_run.params.steps;
  if (o.resume && fs::exists(ref_path)) {
    st.reference = trial_from_json(read_json(ref_path), ref_path);
  } else {
    family.log("forward reference at " + std::to_string(st.forward_size) + ": " +
               std::to_string(ref_params.steps) + " steps");
    st.reference =
        run_trial(*family.state(st.forward_size).runner, ref_params, st.tolerances, o.stop);
    throw_if_stopped(o);  // a run the stop may have cut short
    st.reference.phase = TrialPhase::reference;
    write_file_atomic(ref_path, to_json(st.reference).dump(2) + "\n");
  }
  const double ref_peak = st.reference.score.criteria.peak_stress_yy;
  st.law_peak_error = ref_peak != 0.0
                          ? (std::abs(law_run.score.criteria.peak_stress_yy) - std::abs(ref_peak)) /
                                std::abs(ref_peak)
                          : 0.0;
}

/// Steps 1 to 4 in order, the calibrations with `calibration`'s options
/// (st.tolerances are theirs: the step searches and the forward reference
/// are scored as the calibrations were); StudyStopped when a stop cut one
/// short.
void run_steps(ScalingFamily& family, const CalibrationOptions& calibration,
               const ScalingStudyOptions& o, ScalingStudy& st) {
  for (int64_t n : st.calibrated_sizes) {
    throw_if_stopped(o);
    std::optional<ScalingSize> r = calibrate_size(family, calibration, o, n);
    if (!r) throw StudyStopped{};
    st.results[n] = std::move(*r);
  }
  const ScalingSize ref = st.results.at(st.ref_size);
  if (!ref.success)
    throw std::runtime_error("the REV (size " + std::to_string(st.ref_size) +
                             ") did not calibrate: no multipliers to carry (see " + o.work_dir +
                             ")");

  // At a size beyond the calibrated ones the search starts at the
  // candidate's prediction: that first run is the candidate's forward check.
  for (int64_t n : o.sizes) {
    ScalingSize& r = st.results[n];
    r.requested = n;
    if (n == st.ref_size) {
      r.fixed.found = true;
      r.fixed.steps = r.best.steps;
      continue;
    }
    throw_if_stopped(o);
    fixed_multipliers(family, o, ref, st.candidate, st.tolerances, n, r);
  }
  fit_laws(st);
  const ScalingSize& fwd = st.results[st.forward_size];
  throw_if_stopped(o);
  if (st.forward_size > o.calibrate_max && !fwd.fixed.trials.empty())
    forward_check(family, o, st, fwd.fixed.trials.front());
}

/// The counts the sizes make (ScalingFamily::made_count) rise with the sizes: two
/// sizes that make one count would calibrate (or run) one sample twice, and
/// a forward size that makes no more than the REV would check nothing.
void check_made_counts(ScalingFamily& family, const ScalingStudyOptions& o, int dimension) {
  const std::string noun = dimension == 3 ? " spheres" : " particles";
  const std::string rounding = family.rounding();
  const std::string why = rounding.empty() ? "" : " (" + rounding + ")";
  int64_t below = 0, below_made = 0;
  for (int64_t n : o.sizes) {
    const int64_t made = family.made_count(n);
    // The forward size against the REV (the size below it, when calibrated).
    const bool forward = n == o.sizes.back() && below <= o.calibrate_max;
    const std::string then =
        forward ? ": the forward size must make more than the REV it checks the law from"
                : ": each size must make a count of its own";
    if (below > 0 && made == below_made)
      throw InputError("--sizes", "",
                       std::to_string(below) + " and " + std::to_string(n) + " both make " +
                           std::to_string(made) + noun + why + then);
    if (below > 0 && made < below_made)
      throw InputError("--sizes", "",
                       std::to_string(n) + " makes " + std::to_string(made) + noun +
                           ", fewer than the " + std::to_string(below_made) + " " +
                           std::to_string(below) + " makes" + why + then);
    below = n, below_made = made;
  }
}

/// A random family's sizes are gases of n particles at the config's
/// aspect: each must be one that consolidates, by the rule the config's
/// assembly.count is held to (gas_layers_fault), or the study calibrates
/// a sample that never comes to rest.
void check_gas_sizes(const SceneConfig& config, const ScalingStudyOptions& o) {
  if (config.assembly.type != "random") return;
  for (int64_t n : o.sizes) {
    const std::string problem = gas_layers_problem(config.dimension, static_cast<int>(n),
                                                   config.assembly.aspect, "assembly.aspect");
    if (!problem.empty()) throw InputError("--sizes", "", size_label(n) + ": " + problem);
  }
}

/// The plan of sizes alone (check_scaling_sizes(options)).
void check_plan(const ScalingStudyOptions& o) {
  const auto calibrated = std::count_if(o.sizes.begin(), o.sizes.end(),
                                        [&](int64_t n) { return n <= o.calibrate_max; });
  if (calibrated < 2)
    throw InputError(
        "--sizes", "",
        "needs at least two sizes <= --calibrate-max (" + std::to_string(o.calibrate_max) + ")");
  // The largest size runs the law carried from the REV: the study's proof.
  // Calibrated, it would check nothing. (Sorted sizes: a largest size above
  // --calibrate-max also has a calibrated size, the REV, below it.)
  if (o.sizes.back() <= o.calibrate_max)
    throw InputError("--sizes", "",
                     "the forward check needs a size above --calibrate-max (" +
                         std::to_string(o.calibrate_max) +
                         "): every size given is calibrated, none runs the law carried from the "
                         "REV");
}

}  // namespace

void check_scaling_sizes(const ScalingStudyOptions& o) { check_plan(o); }

CheckedScalingStudy::CheckedScalingStudy(std::unique_ptr<ScalingFamily> family)
    : family_(std::move(family)) {}
CheckedScalingStudy::CheckedScalingStudy(CheckedScalingStudy&&) noexcept = default;
CheckedScalingStudy& CheckedScalingStudy::operator=(CheckedScalingStudy&&) noexcept = default;
CheckedScalingStudy::~CheckedScalingStudy() = default;

CheckedScalingStudy check_scaling_sizes(const SceneConfig& config, const ScalingStudyOptions& o) {
  check_plan(o);
  check_gas_sizes(config, o);
  auto family = std::make_unique<ScalingFamily>(config, o);
  check_made_counts(*family, o, config.dimension);
  family->check_assemblies();
  return CheckedScalingStudy(std::move(family));
}

ScalingStudy run_scaling_study(const SceneConfig& config, const ScalingStudyOptions& o) {
  return run_scaling_study(check_scaling_sizes(config, o), o);
}

ScalingStudy run_scaling_study(CheckedScalingStudy checked, const ScalingStudyOptions& o) {
  if (!checked.family_) throw std::invalid_argument("run_scaling_study: a study already run");
  ScalingFamily& family = *checked.family_;
  family.run_with(o);
  const SceneConfig& config = family.config();
  const auto t_start = std::chrono::steady_clock::now();
  ScalingStudy st;
  st.scene = config.name;
  st.dimension = config.dimension;
  st.sizes = o.sizes;
  st.sizes_text = o.sizes_text;
  st.calibrate_max = o.calibrate_max;
  st.accuracy = config.calibration.accuracy;
  st.resumed = o.resume;
  // The law the study checks forward and carries unless it falls short:
  // the dimension's default (Tu & Andrade's linear law for disks, N^(2/3)
  // for spheres, reports/scaling-3d.md §4).
  st.candidate = default_law(config.dimension);
  // The tolerances every run of the study is scored with: the
  // calibrations' (the dimension's defaults), recorded in scaling.json and
  // scaling.md.
  const CalibrationOptions calibration = CalibrationOptions::from(config);
  st.tolerances = calibration.tolerances;
  for (int64_t n : o.sizes)
    if (n <= o.calibrate_max) st.calibrated_sizes.push_back(n);
  st.forward_size = o.sizes.back();
  // The REV the law is carried from: the largest calibrated size below the
  // largest size.
  for (int64_t n : st.calibrated_sizes)
    if (n < st.forward_size) st.ref_size = n;

  st.from_file = family.from_file();
  st.family = st.from_file ? "REVs cut from a particle file" : config.assembly.type + " generator";
  make_output_dir(o.work_dir);
  family.log("family: " +
             (st.from_file
                  ? "REVs cut from a " + std::to_string(family.file_particles()) + "-particle file"
                  : config.assembly.type + " generator of " + config.name) +
             "; sizes " + o.sizes_text + "; calibrated up to " + std::to_string(o.calibrate_max) +
             "; the REV whose multipliers are carried: " + std::to_string(st.ref_size));

  // A stop (o.stop) takes effect within a calibration, a consolidation, a
  // step search or the forward reference (at the run's next check or
  // monitoring point) and between the steps of the study: whatever finished
  // is in the work folder, the step it cut wrote nothing.
  try {
    run_steps(family, calibration, o, st);
  } catch (const StudyStopped&) {
    st.interrupted = true;
    return st;
  }
  st.forward_ok =
      st.have_forward && st.law_run.score.passed && std::abs(st.law_peak_error) <= st.accuracy;
  // The law upscaling uses: the candidate while the forward check confirms
  // it (a smaller measured exponent would save steps, but it was fitted on
  // the forward size itself and has no independent check here); the
  // measured exponent when the candidate falls short.
  const bool candidate = st.forward_ok || st.measured.exponent <= st.candidate.exponent;
  st.chosen = candidate ? st.candidate : st.measured;
  if (st.dimension == 3 && candidate)
    st.chosen.source += "; demcal scaling " + st.scene +
                        (st.forward_ok ? ": checked forward at " : ": forward check FAILED at ") +
                        std::to_string(st.results[st.forward_size].particles) + " spheres";
  st.wall_time_s = seconds_since(t_start);
  return st;
}

json to_json(const ScalingStudy& st, const SceneConfig& config) {
  json sizes_json = json::array();
  for (int64_t n : st.sizes) sizes_json.push_back(to_json(st.results.at(n)));
  auto spread_json = [](const Spread& s) {
    return json{{"mean", s.mean}, {"min", s.min}, {"max", s.max}, {"relative", s.relative}};
  };
  auto fit_json = [](const LinearFit& lin, const LinearFit& pw) {
    return json{
        {"linear", {{"slope", lin.slope}, {"intercept", lin.intercept}, {"r2", lin.r2}}},
        {"power",
         {{"exponent", pw.slope}, {"coefficient", std::exp(pw.intercept)}, {"r2_log", pw.r2}}}};
  };
  const ScalingSize& ref = st.results.at(st.ref_size);
  const ScalingSize& fwd = st.results.at(st.forward_size);
  return {{"schema", "demcal.scaling/1"},
          {"scene", st.scene},
          {"family", st.family},
          {"sizes", st.sizes},
          {"calibrate_max", st.calibrate_max},
          {"results", sizes_json},
          {"fit_calibrated", fit_json(st.lin_cal, st.pow_cal)},
          {"fit_fixed_multipliers_all", fit_json(st.lin_fix, st.pow_fix)},
          {"fit_fixed_multipliers_from_rev", fit_json(st.lin_rep, st.pow_rep)},
          {"reference_rev", {{"particles", ref.particles}, {"params", to_json(ref.best)}}},
          {"multiplier_spread",
           {{"dt_ratio", spread_json(st.alpha)},
            {"damping_ratio_translation", spread_json(st.zeta_t)},
            {"damping_ratio_rotation", spread_json(st.zeta_r)}}},
          {"measured_law", to_json(st.measured)},
          {"dimension", st.dimension},
          {"exponent_linear_size", st.dimension * st.measured.exponent},
          {"law", to_json(st.chosen)},
          {"candidate_law", to_json(st.candidate)},
          {"linear_holds", st.linear_holds},
          {"candidate_holds", law_holds(st.measured.exponent, st.candidate)},
          {"forward",
           {{"particles", fwd.particles},
            {"from_rev", ref.particles},
            {"law", to_json(st.candidate)},
            {"run", st.have_forward ? to_json(st.law_run) : json()},
            {"reference", st.have_forward ? to_json(st.reference) : json()},
            {"peak_error_vs_reference", st.law_peak_error},
            {"accuracy", st.accuracy},
            {"passed", st.forward_ok}}},
          {"tolerances", to_json(st.tolerances)},
          {"wall_time_s", st.wall_time_s},
          {"config", to_json(config)},
          {"version", DEMCAL_VERSION}};
}

}  // namespace demcal
