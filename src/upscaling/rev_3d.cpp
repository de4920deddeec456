// The REV in 3D (rev_3d.hpp): the box cut, the resampled gas, the
// consolidation and the comparison. The measures, the verdict and the JSON
// are the 2D ones (rev.cpp).
#include "demcal/upscaling/rev_3d.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "cut_window.hpp"
#include "demcal/io/input_error.hpp"

namespace demcal {

SphereAssembly cut_rev(const SphereAssembly& proto, int64_t count, double aspect) {
  const int n = proto.size();
  detail::check_rev_count(count, n, "spheres");
  // The window's half-edges are s·e[d]/2, centred on the box centre:
  // centre i is inside from the scale critical(i) on.
  std::array<double, 3> centre, edge;
  for (int d = 0; d < 3; ++d) {
    centre[d] = 0.5 * (proto.lo[d] + proto.hi[d]);
    edge[d] = proto.hi[d] - proto.lo[d];
  }
  if (aspect > 0.0) edge = {aspect, aspect, 1.0};
  const double scale = std::max({edge[0], edge[1], edge[2]});
  for (double& e : edge) e = std::max(e / scale, 1e-12);  // the largest is 1
  const std::vector<double>* pos[3] = {&proto.x, &proto.y, &proto.z};
  auto critical = [&](int i) {
    double t = 0.0;
    for (int d = 0; d < 3; ++d) t = std::max(t, 2.0 * std::abs((*pos[d])[i] - centre[d]) / edge[d]);
    return t;
  };
  const double s = detail::window_scale(n, count, critical);
  SphereAssembly a;
  for (int i = 0; i < n; ++i) {
    if (critical(i) > s) continue;
    a.x.push_back(proto.x[i]);
    a.y.push_back(proto.y[i]);
    a.z.push_back(proto.z[i]);
    a.r.push_back(proto.r[i]);
  }
  std::vector<double>* kept[3] = {&a.x, &a.y, &a.z};
  for (int d = 0; d < 3; ++d) {
    a.lo[d] = std::numeric_limits<double>::infinity();
    a.hi[d] = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < a.size(); ++i) {
      a.lo[d] = std::min(a.lo[d], (*kept[d])[i] - a.r[i]);
      a.hi[d] = std::max(a.hi[d], (*kept[d])[i] + a.r[i]);
    }
  }
  return a;
}

double rev_gas_aspect(const SphereAssembly& proto) {
  const double h = proto.hi[2] - proto.lo[2];
  return h > 0.0 ? std::sqrt((proto.hi[0] - proto.lo[0]) * (proto.hi[1] - proto.lo[1])) / h : 1.0;
}

SphereAssembly generate_rev(const SphereAssembly& proto, int64_t count, uint64_t seed) {
  if (count < 2) throw InputError("REV", "particles", "needs at least 2 particles");
  if (count > kMaxParticles)
    throw InputError("REV", "particles", std::string("at most ") + kMaxParticlesWhy);
  std::mt19937_64 rng(seed);
  return sphere_gas(resample_radii(proto.r, count, seed), rev_gas_aspect(proto), rng);
}

SphereAssembly sphere_assembly_of(const SphereWorld& world) {
  SphereAssembly a;
  a.x.assign(world.x().begin(), world.x().end());
  a.y.assign(world.y().begin(), world.y().end());
  a.z.assign(world.z().begin(), world.z().end());
  a.r.assign(world.radius().begin(), world.radius().end());
  for (int d = 0; d < 3; ++d) {
    a.lo[d] = world.wall(static_cast<SphereWallSide>(2 * d)).position;
    a.hi[d] = world.wall(static_cast<SphereWallSide>(2 * d + 1)).position;
  }
  return a;
}

SphereRevResult make_rev(const SceneConfig& config, const SphereAssembly& prototype,
                         const RevOptions& o) {
  return make_rev(prototype, o,
                  [&](const SphereAssembly& raw) { return consolidate_triaxial(config, raw); });
}

SphereRevResult make_rev(const SphereAssembly& prototype, const RevOptions& o,
                         const std::function<TriaxialState(const SphereAssembly&)>& consolidated) {
  return make_rev(prototype, o, unconsolidated_rev(prototype, o), consolidated);
}

SphereAssembly unconsolidated_rev(const SphereAssembly& prototype, const RevOptions& o) {
  if (o.method != "cut" && o.method != "generate")
    throw InputError("REV", "method", "must be cut or generate, got \"" + o.method + "\"");
  return o.method == "cut" ? cut_rev(prototype, o.particles, o.aspect)
                           : generate_rev(prototype, o.particles, o.seed);
}

SphereRevResult make_rev(const SphereAssembly& prototype, const RevOptions& o,
                         const SphereAssembly& raw,
                         const std::function<TriaxialState(const SphereAssembly&)>& consolidated) {
  SphereRevResult out{o.method, {}, consolidated(raw), {}};
  out.assembly = sphere_assembly_of(out.state.world);
  out.representativeness = compare(packing_stats(out.state.world), packing_stats(prototype),
                                   out.assembly.r, prototype.r);
  return out;
}

}  // namespace demcal
