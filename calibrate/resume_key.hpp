// What a command's --resume must match: the settings an earlier run wrote to
// DIR/resume.json (`demcal calibrate` and `demcal scaling`). Reusing results
// of other settings, or of another build, would give another run's answer.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "demcal/scene/config.hpp"

namespace demcal::cli {

/// The build's part of every key: demcal's version and the SHA-256 of the
/// running program (program_digest, as the consolidation cache's key), since
/// the version is not bumped for every change of a law or of the rounding.
void add_build(nlohmann::json& key);

/// A particle file's part of a key: the SHA-256 of its contents under
/// `name` (nothing for an empty path). The config's text names a file, not
/// what it holds: edited under the same name, it makes other trials. A file
/// that cannot be read is the config's error at `field` (require_config_file).
void add_file_digest(nlohmann::json& key, const std::string& name, const SceneConfig& config,
                     const std::string& field, const std::string& path);

/// The key written to DIR/resume.json at a fresh start.
void write_resume_key(const std::string& dir, const nlohmann::json& key);

/// --resume into `dir`: DIR/resume.json must hold every field of `key` with
/// the same value, or one InputError naming the file and the first field
/// that differs (exit 2, nothing changed). `what` names the results reused
/// ("the trials in DIR/trials.jsonl"), `same` what must match ("config,
/// --set, --accuracy, --strategy and demcal build"), `fresh` the way out.
void require_same_run(const std::string& dir, const nlohmann::json& key, const std::string& what,
                      const std::string& same, const std::string& fresh);

}  // namespace demcal::cli
