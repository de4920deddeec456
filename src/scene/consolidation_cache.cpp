#include "demcal/scene/consolidation_cache.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <type_traits>

#include "demcal/io/files.hpp"

namespace demcal {

namespace fs = std::filesystem;

namespace {

// The entry's first bytes; the number is the layout of what follows ('2'
// since the world's bytes come first and the entry holds 2D or 3D states).
constexpr std::string_view kMagic = "demcal consolidated state 2\n";
constexpr size_t kDigestHex = 64;  // SHA-256 in hex

std::string hex_float(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

/// The whole file, read at once into a string of its size (a character at a
/// time, the 3.7 MB program took 0.1 s); nothing when it cannot be read.
std::optional<std::string> read_whole(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return std::nullopt;
  const std::streamoff size = in.tellg();
  if (size < 0) return std::nullopt;
  std::string bytes(static_cast<size_t>(size), '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), size) || in.peek() != std::ifstream::traits_type::eof())
    return std::nullopt;  // cut short, or grown meanwhile
  return bytes;
}

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

/// Reads what put() wrote; false once the bytes run out.
class Cursor {
 public:
  explicit Cursor(std::string_view bytes) : in_(bytes) {}
  template <class T>
  bool get(T& v) {
    if (sizeof(T) > in_.size() - at_) return false;
    std::memcpy(&v, in_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return true;
  }
  bool get(std::string_view& v, size_t n) {
    if (n > in_.size() - at_) return false;
    v = in_.substr(at_, n);
    at_ += n;
    return true;
  }
  size_t at() const { return at_; }

 private:
  std::string_view in_;
  size_t at_ = 0;
};

/// The fields of a consolidated state beside its world, in the entry's
/// order: the box after consolidation is the protocol's (2D: width, height;
/// 3D: the three edges).
template <class State, class Field>
void visit_fields(State& s, Field&& field) {
  field(s.steps);
  if constexpr (std::is_same_v<std::remove_const_t<State>, TriaxialState>) {
    for (auto& edge : s.extent0) field(edge);
  } else {
    field(s.width0);
    field(s.height0);
  }
  field(s.stress_error);
  field(s.unbalanced_ratio);
  field(s.converged);
}

template <class State>
std::string encode(const std::string& key, const State& s) {
  std::string payload;
  const std::string world = s.world.save_state();
  put(payload, static_cast<uint64_t>(world.size()));
  payload += world;
  visit_fields(s, [&](const auto& v) { put(payload, v); });
  std::string out(kMagic);
  put(out, static_cast<uint64_t>(key.size()));
  out += key;
  put(out, static_cast<uint64_t>(payload.size()));
  out += payload;
  out += sha256_hex(out);
  return out;
}

template <class State>
std::optional<State> decode(std::string_view bytes, const std::string& key) {
  if (bytes.size() < kMagic.size() + kDigestHex || bytes.substr(0, kMagic.size()) != kMagic)
    return std::nullopt;
  const std::string_view body = bytes.substr(0, bytes.size() - kDigestHex);
  if (sha256_hex(body) != bytes.substr(body.size())) return std::nullopt;
  Cursor c(body.substr(kMagic.size()));
  uint64_t key_size = 0, payload_size = 0;
  std::string_view stored_key, payload;
  if (!c.get(key_size) || !c.get(stored_key, key_size) || stored_key != key ||
      !c.get(payload_size) || !c.get(payload, payload_size) ||
      c.at() != body.size() - kMagic.size())
    return std::nullopt;
  Cursor p(payload);
  uint64_t world_size = 0;
  std::string_view world;
  if (!p.get(world_size) || !p.get(world, world_size)) return std::nullopt;
  // World::load_state or SphereWorld::load_state: throws when it does not read.
  State s{decltype(State::world)::load_state(world)};
  bool whole = true;
  visit_fields(s, [&](auto& v) { whole = whole && p.get(v); });
  if (!whole || p.at() != payload.size()) return std::nullopt;
  return s;
}

/// The key: the protocol's line, then the lines every consolidation shares
/// around the assembly's (consolidation_key of disks and of spheres).
std::string key_of(const SceneConfig& config, std::string_view protocol,
                   std::string_view assembly) {
  std::ostringstream k;
  k << "demcal " << DEMCAL_VERSION << " consolidation " << protocol << "\n"
    << "program " << program_digest() << "\n"
    << "simd " << kernel_simd() << "\n"
    << assembly;
  const Material& m = config.material;
  k << "material";
  for (double d : {m.density, m.thickness, m.particle.kn, m.particle.kt, m.particle.friction,
                   m.wall.kn, m.wall.kt, m.wall.friction, m.contact_damping_ratio})
    k << " " << hex_float(d);
  const TestSpec& t = config.test;
  k << "\ntest " << hex_float(t.lateral_stress) << " " << hex_float(t.servo_gain) << " "
    << hex_float(t.consolidation_tolerance) << " " << hex_float(t.consolidation_unbalanced) << " "
    << t.consolidation_max_steps << "\nlock_rotation " << config.algorithm.lock_rotation;
  const KernelOptions o;
  k << "\nkernel " << hex_float(o.skin_ratio) << " " << hex_float(o.max_overlap_ratio) << " "
    << o.check_interval << " " << hex_float(o.max_energy_ratio) << " "
    << hex_float(o.max_energy_created) << " " << o.energy_check_interval << " " << o.threads
    << "\n";
  return k.str();
}

/// The assembly's line: its particles' count and a SHA-256 of their numbers
/// and the box's.
std::string assembly_line(size_t count, const char* particles, const std::string& numbers) {
  return "assembly " + std::to_string(count) + " " + particles + " " + sha256_hex(numbers) + "\n";
}

template <class State>
std::optional<State> load(const std::string& dir, const std::string& key) {
  try {
    const auto bytes = read_whole(consolidation_cache_path(dir, key));
    if (!bytes) return std::nullopt;
    auto state = decode<State>(*bytes, key);
    if (state) state->from_cache = true;
    return state;
  } catch (const std::exception&) {
    return std::nullopt;  // bytes that do not read as a state: rebuilt
  }
}

template <class State>
bool store(const std::string& dir, const std::string& key, const State& state) {
  static std::atomic<int> counter{0};
  const std::string path = consolidation_cache_path(dir, key);
  // A name of this process and write of its own (two threads of one process
  // may store the same key at once).
  const std::string tmp = (fs::path(dir) / temporary_name(std::to_string(counter++) + "-" +
                                                          fs::path(path).filename().string()))
                              .string();
  try {
    fs::create_directories(dir);
    const std::string bytes = encode(key, state);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) return false;
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
      if (n <= 0) break;
      done += static_cast<size_t>(n);
    }
    const bool written = ::close(fd) == 0 && done == bytes.size();
    if (written && std::rename(tmp.c_str(), path.c_str()) == 0) return true;
    ::unlink(tmp.c_str());
  } catch (const std::exception&) {
    ::unlink(tmp.c_str());
  }
  return false;
}

}  // namespace

const std::string& program_digest() {
  static const std::string digest = [] {
    const auto bytes = read_whole("/proc/self/exe");
    return bytes ? sha256_hex(*bytes) : std::string();
  }();
  return digest;
}

std::string consolidation_cache_dir() {
  if (const char* d = std::getenv("DEMCAL_CACHE_DIR"))
    return std::string(d) == "off" ? std::string() : std::string(d);
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x)
    return (fs::path(x) / "demcal").string();
  if (const char* h = std::getenv("HOME"); h && *h)
    return (fs::path(h) / ".cache" / "demcal").string();
  return {};
}

std::string consolidation_key(const SceneConfig& config, const Assembly& a) {
  std::string numbers;
  for (const auto* v : {&a.x, &a.y, &a.r})
    for (double d : *v) put(numbers, d);
  for (double d : {a.left, a.right, a.bottom, a.top}) put(numbers, d);
  return key_of(config, "biaxial", assembly_line(a.x.size(), "disks", numbers));
}

std::string consolidation_key(const SceneConfig& config, const SphereAssembly& a) {
  std::string numbers;
  for (const auto* v : {&a.x, &a.y, &a.z, &a.r})
    for (double d : *v) put(numbers, d);
  for (const auto* box : {&a.lo, &a.hi})
    for (double d : *box) put(numbers, d);
  return key_of(config, "triaxial", assembly_line(a.x.size(), "spheres", numbers));
}

std::string consolidation_cache_path(const std::string& dir, const std::string& key) {
  return (fs::path(dir) / ("consolidated-" + sha256_hex(key) + ".bin")).string();
}

std::optional<ConsolidatedState> load_consolidated(const std::string& dir, const std::string& key) {
  return load<ConsolidatedState>(dir, key);
}

std::optional<TriaxialState> load_consolidated_triaxial(const std::string& dir,
                                                        const std::string& key) {
  return load<TriaxialState>(dir, key);
}

bool store_consolidated(const std::string& dir, const std::string& key,
                        const ConsolidatedState& state) {
  return store(dir, key, state);
}

bool store_consolidated(const std::string& dir, const std::string& key,
                        const TriaxialState& state) {
  return store(dir, key, state);
}

}  // namespace demcal
