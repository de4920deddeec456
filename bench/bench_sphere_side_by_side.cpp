// Side-by-side driver for the sphere kernel: an FCC lattice of n×n×n cells
// (4n³ spheres, fcc_packing pre-compressed by 1e-4), μ = 0.3, ζ_t = 0.1,
// ζ_r = 0, α = 0.2, the top wall moving down slowly; after the preload the
// spheres are renumbered to fill the kernel's SIMD blocks, as demcal does
// after a consolidation (--no-order keeps the lattice's numbering); it times
// SphereWorld::step over the run and can write the same scene for LAMMPS
// (bench/lammps/in.sphere_compress reads it; bench/lammps_compare_sphere.sh
// runs both).
//
//   bench_sphere_side_by_side --cells 4 --steps 20000 --preload 2000 [--no-order]
//   bench_sphere_side_by_side --cells 4 --write-lammps /tmp/fcc4 --no-run
//   DEMCAL_SIMD=avx2 bench_sphere_side_by_side --cells 19 --threads 2
//
// Output: one line of key=value pairs (engine, particles, steps, seconds,
// particle_steps_per_s, contacts at the end — LAMMPS must report the same —
// and the SIMD path, threads, neighbour-list rebuilds, the half and mirror
// lists' slot fills and whether the spheres were renumbered).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <string>

#include "demcal/kernel/sphere_world.hpp"
#include "demcal/scene/sphere_packing.hpp"

namespace {

using namespace demcal;

constexpr double kR = 5e-4, kDensity = 2650.0, kKn = 1e8, kKt = 5e7, kMu = 0.3;
constexpr double kAlpha = 0.2, kZeta = 0.1, kStrainRate = 0.05;  // top-wall strain per second

struct Scene {
  SphereAssembly a;
  SphereMaterial material;
  Integration integration;
  double top_speed = 0.0;
};

Scene make_scene(int cells) {
  Scene s;
  s.a = fcc_packing(cells, cells, cells, kR, 1e-4);
  s.material.density = kDensity;
  s.material.particle = {kKn, kKt, kMu};
  s.material.wall = {kKn, kKt, 0.0};
  const double m = kDensity * 4.0 / 3.0 * M_PI * kR * kR * kR;
  s.integration.dt = kAlpha * 2.0 * std::sqrt(m / kKn);
  s.integration.damping_ratio_translation = kZeta;
  s.integration.damping_ratio_rotation = 0.0;
  s.top_speed = -kStrainRate * (s.a.hi[2] - s.a.lo[2]);
  return s;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

void write_lammps(const Scene& s, const std::string& prefix) {
  const SphereAssembly& a = s.a;
  const double pad = 4.0 * kR;
  std::ofstream d(prefix + ".data");
  d << "demcal FCC sphere bench\n\n" << a.size() << " atoms\n1 atom types\n\n";
  const char* axis[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k)
    d << num(a.lo[k] - pad) << " " << num(a.hi[k] + pad) << " " << axis[k] << "lo " << axis[k]
      << "hi\n";
  d << "\nAtoms # sphere\n\n";
  for (int i = 0; i < a.size(); ++i)
    d << i + 1 << " 1 " << num(2.0 * a.r[i]) << " " << num(kDensity) << " " << num(a.x[i]) << " "
      << num(a.y[i]) << " " << num(a.z[i]) << "\n";
  const double m = kDensity * 4.0 / 3.0 * M_PI * kR * kR * kR;
  std::ofstream v(prefix + ".vars");
  v << "variable kn equal " << num(kKn) << "\nvariable kt equal " << num(kKt)
    << "\nvariable mu equal " << num(kMu) << "\nvariable dt equal " << num(s.integration.dt)
    << "\nvariable skin equal " << num(0.3 * kR) << "\nvariable gamma equal "
    << num(kZeta * 2.0 * std::sqrt(kKn * m)) << "\nvariable vtop equal " << num(s.top_speed);
  const char* names[6] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
  for (int k = 0; k < 6; ++k)
    v << "\nvariable " << names[k] << " equal " << num(k % 2 ? a.hi[k / 2] : a.lo[k / 2]);
  v << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  int cells = 4;
  long steps = 20000, preload = 2000;
  int threads = 1;
  std::string lammps_prefix;
  bool run = true, order = true;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    auto value = [&] {
      if (k + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", arg.c_str());
        std::exit(2);
      }
      return std::string(argv[++k]);
    };
    if (arg == "--cells")
      cells = std::atoi(value().c_str());
    else if (arg == "--steps")
      steps = std::atol(value().c_str());
    else if (arg == "--preload")
      preload = std::atol(value().c_str());
    else if (arg == "--threads")
      threads = std::atoi(value().c_str());
    else if (arg == "--write-lammps")
      lammps_prefix = value();
    else if (arg == "--no-run")
      run = false;
    else if (arg == "--no-order")
      order = false;
    else {
      std::fprintf(stderr, "unknown argument %s\n", arg.c_str());
      return 2;
    }
  }
  const Scene s = make_scene(cells);
  if (!lammps_prefix.empty()) write_lammps(s, lammps_prefix);
  if (!run) return 0;
  KernelOptions options;
  options.threads = threads;
  SphereWorld w(s.material, s.a.x, s.a.y, s.a.z, s.a.r, s.a.lo, s.a.hi, options);
  w.set_integration(s.integration);
  w.wall(kZMax).velocity = s.top_speed;
  if (!w.step(preload)) return 1;
  if (order) w.reorder(w.block_friendly_order());
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  if (!w.step(steps)) return 1;
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  std::printf(
      "engine=demcal scene=fcc_%dx%dx%d particles=%d steps=%ld seconds=%.4g cpu_seconds=%.4g "
      "particle_steps_per_s=%.4g contacts=%d rebuilds=%lld simd=%s gather=%s threads=%d "
      "slot_fill=%.3f "
      "mirror_fill=%.3f ordered=%d\n",
      cells, cells, cells, w.size(), steps, sec, cpu, w.size() * static_cast<double>(steps) / sec,
      w.measure().particle_contacts, static_cast<long long>(w.rebuilds()), kernel_simd(),
      kernel_gather(), w.threads(), w.neighbour_slot_fill(), w.mirror_slot_fill(), order ? 1 : 0);
  return 0;
}
