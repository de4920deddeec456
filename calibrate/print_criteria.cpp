#include "print_criteria.hpp"

namespace demcal::cli {

void print_triaxial_criteria(std::ostream& out, const TriaxialCriteria& c, const Criteria& judged) {
  const Criteria& m = judged;
  out << "  force balance " << m.force_balance << " (axial " << m.force_balance_yy << ", lateral x "
      << c.xz.force_balance_xx << ", lateral y " << c.yz.force_balance_xx << ", shear xz "
      << c.xz.force_balance_shear << ", yz " << c.yz.force_balance_shear << ", xy "
      << c.xy.force_balance_shear << ")\n"
      << "  moment balance " << m.moment_balance << " (xz " << c.xz.moment_balance << ", yz "
      << c.yz.moment_balance << ", xy " << c.xy.moment_balance << "; rotational drag "
      << c.rotational_drag << " folded in at " << kRotationalDragTolerance << "), servo " << m.servo
      << " (walls x min " << c.servo_walls[0] << ", x max " << c.servo_walls[1] << ", y min "
      << c.servo_walls[2] << ", y max " << c.servo_walls[3] << "), oscillation " << m.oscillation
      << "\n";
}

}  // namespace demcal::cli
