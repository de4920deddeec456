#include "resume_key.hpp"

#include <filesystem>

#include "demcal/io/files.hpp"
#include "demcal/io/format.hpp"
#include "demcal/io/input_error.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/consolidation_cache.hpp"

namespace demcal::cli {

void add_build(nlohmann::json& key) {
  key["version"] = DEMCAL_VERSION;
  key["program_sha256"] = program_digest();
}

void add_file_digest(nlohmann::json& key, const std::string& name, const SceneConfig& config,
                     const std::string& field, const std::string& path) {
  if (path.empty()) return;
  require_config_file(config, field, path);
  key[name] = sha256_hex(read_text_file(path));
}

void write_resume_key(const std::string& dir, const nlohmann::json& key) {
  write_file_atomic(dir + "/resume.json", key.dump(2) + "\n");
}

void require_same_run(const std::string& dir, const nlohmann::json& key, const std::string& what,
                      const std::string& same, const std::string& fresh) {
  const std::string path = dir + "/resume.json";
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw InputError(path, "",
                     "missing: " + what +
                         " cannot be matched to their settings (an older demcal or another "
                         "command's folder); " +
                         fresh);
  nlohmann::json stored;
  try {
    stored = parse_config_json(read_text_file(path), path);
  } catch (const InputError& e) {
    throw InputError(path, "", std::string(e.what()) + "; " + fresh);
  }
  const auto shown = [](const nlohmann::json& v) {
    return v.is_string() ? quoted_value(v.get<std::string>()) : quoted_value(v.dump());
  };
  for (const auto& [name, value] : key.items())
    if (!stored.is_object() || !stored.contains(name) || stored[name] != value)
      throw InputError(path, name,
                       what + " were run with " +
                           (stored.is_object() && stored.contains(name) ? shown(stored[name])
                                                                        : std::string("nothing")) +
                           ", this run has " + shown(value) +
                           "; --resume reuses only those of the same " + same + ": " + fresh);
}

}  // namespace demcal::cli
