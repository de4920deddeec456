// SphereWorld, the 3D kernel's public face: each call forwards to the
// SphereWorldImpl it owns (sphere_world_impl.hpp). The step and the passes
// run inside SphereWorldImpl, so forwarding costs one call per step(n).
#include <utility>

#include "sphere_world_impl.hpp"

namespace demcal {

SphereWorld::SphereWorld(const SphereMaterial& material, std::span<const double> x,
                         std::span<const double> y, std::span<const double> z,
                         std::span<const double> radius, const std::array<double, 3>& lo,
                         const std::array<double, 3>& hi, KernelOptions options)
    : impl_(std::make_unique<SphereWorldImpl>(material, x, y, z, radius, lo, hi, options)) {}
SphereWorld::SphereWorld(std::unique_ptr<SphereWorldImpl> impl) : impl_(std::move(impl)) {}
SphereWorld::SphereWorld(const SphereWorld& other)
    : impl_(std::make_unique<SphereWorldImpl>(*other.impl_)) {}
SphereWorld::SphereWorld(SphereWorld&& other) noexcept = default;
SphereWorld& SphereWorld::operator=(const SphereWorld& other) {
  if (this != &other) impl_ = std::make_unique<SphereWorldImpl>(*other.impl_);
  return *this;
}
SphereWorld& SphereWorld::operator=(SphereWorld&& other) noexcept = default;
SphereWorld::~SphereWorld() = default;

void SphereWorld::set_integration(const Integration& integration) {
  impl_->set_integration(integration);
}
const Integration& SphereWorld::integration() const { return impl_->integration(); }
const SphereMaterial& SphereWorld::material() const { return impl_->material(); }
const KernelOptions& SphereWorld::options() const { return impl_->options(); }
void SphereWorld::set_options(const KernelOptions& options) { impl_->set_options(options); }
void SphereWorld::set_particle_friction(double mu) { impl_->set_particle_friction(mu); }

bool SphereWorld::step(int64_t n) { return impl_->step(n); }
Divergence SphereWorld::divergence() const { return impl_->divergence(); }
double SphereWorld::energy_created() const { return impl_->energy_created(); }
int64_t SphereWorld::divergence_step() const { return impl_->divergence_step(); }
int64_t SphereWorld::steps_taken() const { return impl_->steps_taken(); }
double SphereWorld::time() const { return impl_->time(); }

SphereMeasures SphereWorld::measure(double strain_rate) const {
  return impl_->measure(strain_rate);
}
ReferenceScales SphereWorld::reference_scales() const { return impl_->reference_scales(); }
StabilityEstimate SphereWorld::stability_estimate(int iterations) const {
  return impl_->stability_estimate(iterations);
}
Eigen::Matrix3d SphereWorld::net_force_moment() const { return impl_->net_force_moment(); }

int SphereWorld::size() const { return impl_->size(); }
std::span<const double> SphereWorld::x() const { return impl_->x(); }
std::span<const double> SphereWorld::y() const { return impl_->y(); }
std::span<const double> SphereWorld::z() const { return impl_->z(); }
std::span<const double> SphereWorld::vx() const { return impl_->vx(); }
std::span<const double> SphereWorld::vy() const { return impl_->vy(); }
std::span<const double> SphereWorld::vz() const { return impl_->vz(); }
std::span<const double> SphereWorld::omega_x() const { return impl_->omega_x(); }
std::span<const double> SphereWorld::omega_y() const { return impl_->omega_y(); }
std::span<const double> SphereWorld::omega_z() const { return impl_->omega_z(); }
std::span<const double> SphereWorld::radius() const { return impl_->radius(); }
double SphereWorld::min_radius() const { return impl_->min_radius(); }
double SphereWorld::max_radius() const { return impl_->max_radius(); }
std::span<const double> SphereWorld::mass() const { return impl_->mass(); }
std::span<const double> SphereWorld::inertia() const { return impl_->inertia(); }
std::span<const double> SphereWorld::fx() const { return impl_->fx(); }
std::span<const double> SphereWorld::fy() const { return impl_->fy(); }
std::span<const double> SphereWorld::fz() const { return impl_->fz(); }
std::span<const double> SphereWorld::torque_x() const { return impl_->torque_x(); }
std::span<const double> SphereWorld::torque_y() const { return impl_->torque_y(); }
std::span<const double> SphereWorld::torque_z() const { return impl_->torque_z(); }

void SphereWorld::set_velocity(int i, const Eigen::Vector3d& v, const Eigen::Vector3d& omega) {
  impl_->set_velocity(i, v, omega);
}
void SphereWorld::set_position(int i, const Eigen::Vector3d& p) { impl_->set_position(i, p); }

SphereWall& SphereWorld::wall(SphereWallSide side) { return impl_->wall(side); }
const SphereWall& SphereWorld::wall(SphereWallSide side) const { return impl_->wall(side); }
double SphereWorld::extent(int axis) const { return impl_->extent(axis); }
double SphereWorld::volume() const { return impl_->volume(); }
Eigen::Vector3d SphereWorld::centre() const { return impl_->centre(); }

std::vector<SphereWorld::ContactView> SphereWorld::contacts() const { return impl_->contacts(); }
int64_t SphereWorld::rebuilds() const { return impl_->rebuilds(); }
double SphereWorld::neighbour_slot_fill() const { return impl_->neighbour_slot_fill(); }
double SphereWorld::mirror_slot_fill() const { return impl_->mirror_slot_fill(); }
void SphereWorld::reorder(std::span<const int> order) { impl_->reorder(order); }
std::vector<int> SphereWorld::block_friendly_order() const { return impl_->block_friendly_order(); }
void SphereWorld::set_threads(int threads) { impl_->set_threads(threads); }
int SphereWorld::threads() const { return impl_->threads(); }
void SphereWorld::update_forces() { impl_->update_forces(); }

std::string SphereWorld::save_state() const { return impl_->save_state(); }
SphereWorld SphereWorld::load_state(std::string_view bytes) {
  return SphereWorld(std::make_unique<SphereWorldImpl>(SphereWorldImpl::load_state(bytes)));
}

}  // namespace demcal
