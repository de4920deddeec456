// World, the 2D kernel's public face: each call forwards to the WorldImpl
// it owns (world_impl.hpp). The step and the passes run inside WorldImpl,
// so the forwarding costs one call per step(n), not per particle.
#include <utility>

#include "demcal/kernel/world.hpp"
#include "world_impl.hpp"

namespace demcal {

World::World(const Material& material, std::span<const double> x, std::span<const double> y,
             std::span<const double> radius, double left, double right, double bottom, double top,
             KernelOptions options)
    : impl_(
          std::make_unique<WorldImpl>(material, x, y, radius, left, right, bottom, top, options)) {}
World::World(std::unique_ptr<WorldImpl> impl) : impl_(std::move(impl)) {}
World::World(const World& other) : impl_(std::make_unique<WorldImpl>(*other.impl_)) {}
World::World(World&& other) noexcept = default;
World& World::operator=(const World& other) {
  if (this != &other) impl_ = std::make_unique<WorldImpl>(*other.impl_);
  return *this;
}
World& World::operator=(World&& other) noexcept = default;
World::~World() = default;

void World::set_integration(const Integration& integration) { impl_->set_integration(integration); }
const Integration& World::integration() const { return impl_->integration(); }
const Material& World::material() const { return impl_->material(); }
const KernelOptions& World::options() const { return impl_->options(); }
void World::set_threads(int threads) { impl_->set_threads(threads); }
void World::set_options(const KernelOptions& options) { impl_->set_options(options); }
void World::reorder(std::span<const int> order) { impl_->reorder(order); }
std::vector<int> World::block_friendly_order() const { return impl_->block_friendly_order(); }
int World::threads() const { return impl_->threads(); }
void World::set_particle_friction(double mu) { impl_->set_particle_friction(mu); }

bool World::step(int64_t n) { return impl_->step(n); }
Divergence World::divergence() const { return impl_->divergence(); }
double World::energy_created() const { return impl_->energy_created(); }
int64_t World::divergence_step() const { return impl_->divergence_step(); }
int64_t World::steps_taken() const { return impl_->steps_taken(); }
double World::time() const { return impl_->time(); }

Measures World::measure(double strain_rate) const { return impl_->measure(strain_rate); }
ReferenceScales World::reference_scales() const { return impl_->reference_scales(); }
StabilityEstimate World::stability_estimate(int iterations) const {
  return impl_->stability_estimate(iterations);
}
Eigen::Matrix2d World::net_force_moment() const { return impl_->net_force_moment(); }

int World::size() const { return impl_->size(); }
std::span<const double> World::x() const { return impl_->x(); }
std::span<const double> World::y() const { return impl_->y(); }
std::span<const double> World::vx() const { return impl_->vx(); }
std::span<const double> World::vy() const { return impl_->vy(); }
std::span<const double> World::rotation() const { return impl_->rotation(); }
std::span<const double> World::omega() const { return impl_->omega(); }
std::span<const double> World::radius() const { return impl_->radius(); }
double World::min_radius() const { return impl_->min_radius(); }
double World::max_radius() const { return impl_->max_radius(); }
std::span<const double> World::mass() const { return impl_->mass(); }
std::span<const double> World::fx() const { return impl_->fx(); }
std::span<const double> World::fy() const { return impl_->fy(); }
std::span<const double> World::torque() const { return impl_->torque(); }

void World::set_velocity(int i, double vx, double vy, double omega) {
  impl_->set_velocity(i, vx, vy, omega);
}
void World::set_position(int i, double x, double y) { impl_->set_position(i, x, y); }

Wall& World::wall(WallSide side) { return impl_->wall(side); }
const Wall& World::wall(WallSide side) const { return impl_->wall(side); }
double World::width() const { return impl_->width(); }
double World::height() const { return impl_->height(); }
double World::volume() const { return impl_->volume(); }
Eigen::Vector2d World::centre() const { return impl_->centre(); }

std::vector<World::ContactView> World::contacts() const { return impl_->contacts(); }
int64_t World::rebuilds() const { return impl_->rebuilds(); }
double World::neighbour_slot_fill() const { return impl_->neighbour_slot_fill(); }
void World::update_forces() { impl_->update_forces(); }

std::string World::save_state() const { return impl_->save_state(); }
World World::load_state(std::string_view bytes) {
  return World(std::make_unique<WorldImpl>(WorldImpl::load_state(bytes)));
}

}  // namespace demcal
