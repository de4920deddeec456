// The plain types a scene hands to a kernel: the material of the particles
// and the walls. No kernel state: a config can hold a Material without
// seeing how a kernel stores its particles.
#pragma once

namespace demcal {

/// Linear spring contact law: normal force kn·δ, incremental tangential
/// spring kt capped by Coulomb friction·|Fn|.
struct ContactLaw {
  double kn = 1e8;        ///< normal stiffness [N/m]
  double kt = 5e7;        ///< tangential stiffness [N/m]
  double friction = 0.3;  ///< Coulomb coefficient μ [-]
};

/// Material of the particles and the walls.
struct Material {
  double density = 2650.0;  ///< ρ [kg/m³]
  double thickness = 1.0;   ///< disk = cylinder of thickness t [m]
  ContactLaw particle{1e8, 5e7, 0.3};
  ContactLaw wall{1e8, 5e7, 0.0};  ///< walls are frictionless by default
  /// Local (contact) viscous damping on the normal force: a dashpot of
  /// contact_damping_ratio × its critical value 2·sqrt(kn·m_eff) (m_eff the
  /// pair's reduced mass, the particle's mass against a wall), so that an
  /// isolated two-disk collision is a linear oscillator of that damping
  /// ratio. The dashpot never pulls (the normal force is clamped at 0). Off
  /// by default: the paper's damping is global.
  double contact_damping_ratio = 0.0;
};

}  // namespace demcal
