// Scoring a triaxial (3D) run: the criteria of the three coordinate planes
// and summary.json. The tolerances are the 2D ones until issue #18
// validates 3D tolerances; the verdict says so (kTriaxialVerdictNote).
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "demcal/scene/config.hpp"
#include "demcal/scene/triaxial.hpp"
#include "demcal/scoring/scoring.hpp"

namespace demcal {

/// The 3D criteria, from the 2D ones of scoring.hpp: force balance, servo,
/// oscillation and moment balance in the xz and yz planes (each exactly the
/// biaxial measure: axial component against its own scale, lateral against
/// σ3), and for the horizontal pair the symmetric xy shear gap (up to the
/// axial peak, as every gap), its noise, and the xy moment balance.
/// `combined` holds the largest of each, for the 2D tolerances.
struct TriaxialCriteria {
  Criteria xz, yz, xy;
  Criteria combined;
};

TriaxialCriteria compute_triaxial_criteria(const std::vector<TriaxialPoint>& series, double s3);

/// What `demcal run` says of a 3D verdict: measured against the 2D tolerances.
extern const char* const kTriaxialVerdictNote;

/// summary.json of a triaxial run (`demcal run` on a 3D config).
nlohmann::json triaxial_run_summary(const SceneConfig& config, const TriaxialState& state,
                                    const TriaxialResult& run, const TriaxialCriteria& c,
                                    const Tolerances& t, const Excesses& e, bool within);

}  // namespace demcal
