// Side-by-side driver: runs one scene of bench_scene.hpp in demcal for a
// number of steps and prints its throughput, and can write the same scene as
// a LAMMPS data file + variables file (bench/lammps/in.compress reads them).
//
//   bench_side_by_side --scene hex --n 400 --steps 50000 --preload 2000
//   bench_side_by_side --scene hex --n 400 --write-lammps /tmp/hex400 --no-run
//   bench_side_by_side --scene hex --n 100000 --steps 400 --threads 2
//
// Output: one line of key=value pairs, e.g.
//   engine=demcal scene=hex_20x20 particles=400 steps=50000 seconds=0.31
//   cpu_seconds=0.31 particle_steps_per_s=6.4e+07 contacts=1141 wall_contacts=80
//   Wxx_pair=... Wyy_pair=... rebuilds=...
// W_pair = Σ over particle–particle contacts of (x_i − x_j) ⊗ f_ij (f_ij =
// force on i from j), compressive positive [N·m]: the pair virial, which
// LAMMPS reports as −Σ stress/atom (pair) — the cross-check that both codes
// see the same contact network under the same load.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <numbers>
#include <string>

#include "bench_scene.hpp"

namespace {

void usage() {
  std::fprintf(stderr,
               "usage: bench_side_by_side [--scene hex|random] [--n N] [--steps S] "
               "[--preload P] [--threads T] [--write-lammps PREFIX] [--no-run]\n");
}

// LAMMPS data (atom_style sphere) + variables for bench/lammps/in.compress.
void write_lammps(const demcal_bench::Scene& s, const demcal::World& w, const std::string& prefix,
                  int64_t steps, int64_t preload) {
  const double margin = 5.0 * demcal_bench::kRadius;
  const double rho = s.material.density, t = s.material.thickness;
  {
    std::ofstream f(prefix + ".data");
    f.precision(17);
    f << "LAMMPS data file: demcal bench scene " << s.name << "\n\n";
    f << s.x.size() << " atoms\n1 atom types\n\n";
    f << s.left - margin << " " << s.right + margin << " xlo xhi\n";
    f << s.bottom - margin << " " << s.top + margin << " ylo yhi\n";
    f << "-0.01 0.01 zlo zhi\n\nAtoms # sphere\n\n";
    for (size_t i = 0; i < s.x.size(); ++i) {
      // atom_style sphere: mass = 4/3·π·r³·density. Choose density so that the
      // mass is the disk's ρ·π·r²·t. (The moment of inertia stays LAMMPS's
      // sphere value 0.4·m·r², not the disk's 0.5·m·r².)
      const double r = s.r[i];
      const double dens = 0.75 * rho * t / r;
      f << i + 1 << " 1 " << 2.0 * r << " " << dens << " " << s.x[i] << " " << s.y[i] << " 0\n";
    }
  }
  // Mean per-particle critical damping, as one global viscous coefficient.
  double gamma = 0.0, mass_sum = 0.0;
  const double areal_density = disk_areal_density(s.material, w.integration().mass_scaling);
  for (size_t i = 0; i < s.x.size(); ++i) {
    const double m = demcal::disk_mass(areal_density, s.r[i]);
    mass_sum += m;
    gamma += w.integration().damping_ratio_translation *
             demcal::critical_damping_translation(s.material.particle.kn, m);
  }
  gamma /= static_cast<double>(s.x.size());
  std::ofstream v(prefix + ".vars");
  v.precision(17);
  v << "# demcal bench scene " << s.name << " (written by bench_side_by_side)\n";
  v << "variable kn equal " << s.material.particle.kn << "\n";
  v << "variable kt equal " << s.material.particle.kt << "\n";
  v << "variable mu equal " << s.material.particle.friction << "\n";
  v << "variable kw equal " << s.material.wall.kn << "\n";
  v << "variable ktw equal " << s.material.wall.kt << "\n";
  v << "variable muw equal " << s.material.wall.friction << "\n";
  v << "variable dt equal " << w.integration().dt << "\n";
  v << "variable gamma equal " << gamma << "\n";
  v << "variable skin equal "
    << w.options().skin_ratio * demcal_bench::kRadius * (s.name.rfind("random", 0) == 0 ? 0.8 : 1.0)
    << "\n";
  v << "variable wleft equal " << s.left << "\n";
  v << "variable wright equal " << s.right << "\n";
  v << "variable wbottom equal " << s.bottom << "\n";
  v << "variable wtop equal " << s.top << "\n";
  v << "variable vtop equal " << w.wall(demcal::kTop).velocity << "\n";
  v << "variable nsteps equal " << steps << "\n";
  v << "variable npre equal " << preload << "\n";
  v << "variable mass_total equal " << mass_sum << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_kind = "hex", lammps_prefix;
  int n = 400, threads = 1;
  int64_t steps = 10000, preload = 2000;
  bool run = true;
  for (int a = 1; a < argc; ++a) {
    auto next = [&]() -> const char* {
      if (a + 1 >= argc) {
        usage();
        std::exit(2);
      }
      return argv[++a];
    };
    if (!std::strcmp(argv[a], "--scene"))
      scene_kind = next();
    else if (!std::strcmp(argv[a], "--n"))
      n = std::atoi(next());
    else if (!std::strcmp(argv[a], "--steps"))
      steps = std::atoll(next());
    else if (!std::strcmp(argv[a], "--preload"))
      preload = std::atoll(next());
    else if (!std::strcmp(argv[a], "--write-lammps"))
      lammps_prefix = next();
    else if (!std::strcmp(argv[a], "--threads"))
      threads = std::atoi(next());
    else if (!std::strcmp(argv[a], "--no-run"))
      run = false;
    else {
      usage();
      return 2;
    }
  }
  if (n < 1 || steps < 1 || preload < 0 || threads < 1 ||
      (scene_kind != "hex" && scene_kind != "random")) {
    usage();
    return 2;
  }
  demcal_bench::Scene scene;
  if (scene_kind == "hex") {
    scene = demcal_bench::hex_scene_n(n);
  } else {
    scene = demcal_bench::random_scene(n);
    scene.material.particle.friction = 0.3;
  }
  auto world = demcal_bench::make_compression_world(scene);
  if (!lammps_prefix.empty()) write_lammps(scene, *world, lammps_prefix, steps, preload);
  if (!run) return 0;
  world->set_threads(threads);

  if (!world->step(preload)) {
    std::fprintf(stderr, "diverged during pre-load: %s\n", demcal::to_string(world->divergence()));
    return 1;
  }
  const int64_t rebuilds0 = world->rebuilds();
  auto cpu_now = [] {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  };
  const double c0 = cpu_now();
  const auto t0 = std::chrono::steady_clock::now();
  const bool ok = world->step(steps);
  const auto t1 = std::chrono::steady_clock::now();
  const double cpu = cpu_now() - c0;
  if (!ok) {
    std::fprintf(stderr, "diverged: %s\n", demcal::to_string(world->divergence()));
    return 1;
  }
  const double sec = std::chrono::duration<double>(t1 - t0).count();
  const auto m = world->measure();
  double wxx = 0.0, wyy = 0.0;
  for (const auto& c : world->contacts()) {
    // force on i: −fn·n + ft·t, t = (−ny, nx); x_i − x_j = −d·n.
    const double d = world->radius()[c.i] + world->radius()[c.j] - c.overlap;
    const double fxi = -c.fn * c.nx - c.ft * c.ny, fyi = -c.fn * c.ny + c.ft * c.nx;
    wxx += -d * c.nx * fxi;
    wyy += -d * c.ny * fyi;
  }
  std::printf(
      "engine=demcal scene=%s particles=%d steps=%lld seconds=%.6f cpu_seconds=%.6f "
      "particle_steps_per_s=%.6e contacts=%d wall_contacts=%d Wxx_pair=%.6e Wyy_pair=%.6e "
      "rebuilds=%lld threads=%d simd=%s gather=%s slot_fill=%.3f\n",
      scene.name.c_str(), world->size(), static_cast<long long>(steps), sec, cpu,
      world->size() * static_cast<double>(steps) / sec, m.particle_contacts, m.wall_contacts, wxx,
      wyy, static_cast<long long>(world->rebuilds() - rebuilds0), world->threads(),
      demcal::kernel_simd(), demcal::kernel_gather(), world->neighbour_slot_fill());
  return 0;
}
