// The on-disk cache of consolidated samples (issue #15): consolidation is
// the same for every check, run, calibrate, sweep, verify and scaling study
// of a scene, so consolidate() (disks, biaxial) and consolidate_triaxial()
// (spheres) keep their result in a folder, keyed by everything that
// determines it, and later commands read it back instead of consolidating
// again. Bit-exact: the state read back is the state the consolidation made
// (World::save_state, SphereWorld::save_state), so every result is
// byte-identical with and without the cache.
//
// The folder: $DEMCAL_CACHE_DIR if set ("off" or "" disables the cache),
// else $XDG_CACHE_HOME/demcal, else $HOME/.cache/demcal. One file per key,
// consolidated-<SHA-256 of the key>.bin, holding the key itself, the state
// and a SHA-256 of both: an entry that does not read back whole (cut,
// damaged, another key under the same name) is ignored and rebuilt, never
// trusted. Entries are written to a temporary and renamed into place, so
// concurrent readers and writers (two commands on the same scene) never see
// half a file; two writers of one key write the same bytes.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <type_traits>

#include "demcal/io/format.hpp"
#include "demcal/scene/biaxial.hpp"
#include "demcal/scene/config.hpp"
#include "demcal/scene/packing.hpp"
#include "demcal/scene/sphere_packing.hpp"
#include "demcal/scene/triaxial.hpp"

namespace demcal {

/// The cache folder from the environment (see the file comment); "" when
/// the cache is off or there is no home folder.
std::string consolidation_cache_dir();

/// SHA-256 of the running program (the build), once per process; "" when it
/// cannot be read (then the version alone stands for the build). Part of
/// the cache's keys and of `demcal calibrate --resume`'s: trials and
/// states of another build are never reused (a build that changed a law,
/// or only the rounding, gives other trials).
const std::string& program_digest();

/// Everything that determines consolidate()'s result, as text: the
/// protocol (biaxial), the assembly it starts from (a SHA-256 of its disks
/// and box, so the assembly spec, seed and particle file's content all
/// enter through what they produce), the material, σ3 and the servo and
/// consolidation settings, the rotation lock, the kernel options and SIMD
/// path, and the program (demcal version and a SHA-256 of the running
/// executable, so that a rebuilt consolidation never reads another build's
/// entries; what the program does after the loop, such as the
/// block-friendly renumbering, enters through it).
std::string consolidation_key(const SceneConfig& config, const Assembly& assembly);
/// The same for consolidate_triaxial(): the protocol (triaxial) and the
/// spheres and six walls in place of the disks and four; the other lines
/// are the 2D key's. A 2D and a 3D key differ in their first line.
std::string consolidation_key(const SceneConfig& config, const SphereAssembly& assembly);

/// The entry file of `key` in `dir`.
std::string consolidation_cache_path(const std::string& dir, const std::string& key);

/// The state stored for `key`, or nothing: no entry, or one that does not
/// read back whole. Never throws.
std::optional<ConsolidatedState> load_consolidated(const std::string& dir, const std::string& key);
/// The same for a triaxial (sphere) state.
std::optional<TriaxialState> load_consolidated_triaxial(const std::string& dir,
                                                        const std::string& key);

/// Store `state` for `key` (the folder is created). Best effort: a folder
/// that cannot be written leaves no entry, and is not an error. Returns
/// whether the entry was written.
bool store_consolidated(const std::string& dir, const std::string& key,
                        const ConsolidatedState& state);
bool store_consolidated(const std::string& dir, const std::string& key, const TriaxialState& state);

/// The cached entry points of both protocols (consolidate(),
/// consolidate_triaxial()): the state stored for this config and assembly
/// in `dir`, else `fresh()`'s, then stored ("" for dir: no cache). A fresh
/// consolidation that fails throws, and nothing is stored.
template <class State, class AnyAssembly, class Fresh>
State consolidate_cached(const std::string& dir, const SceneConfig& config,
                         const AnyAssembly& assembly, Fresh&& fresh) {
  if (dir.empty()) return fresh();
  const auto t0 = std::chrono::steady_clock::now();
  const std::string key = consolidation_key(config, assembly);
  std::optional<State> cached;
  if constexpr (std::is_same_v<State, TriaxialState>)
    cached = load_consolidated_triaxial(dir, key);
  else
    cached = load_consolidated(dir, key);
  if (cached) {
    cached->wall_time_s = seconds_since(t0);
    return std::move(*cached);
  }
  State state = fresh();
  store_consolidated(dir, key, state);
  return state;
}

}  // namespace demcal
