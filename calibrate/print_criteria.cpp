#include "print_criteria.hpp"

#include <sstream>
#include <string>

namespace demcal::cli {

void print_triaxial_criteria(std::ostream& out, const TriaxialCriteria& c, const Criteria& judged) {
  const Criteria& m = judged;
  // A measure the series could not give (`demcal score`): "n/a (why)".
  auto value = [&](const std::map<std::string, std::string>& missing, const char* key, double v) {
    std::ostringstream s;
    s.copyfmt(out);
    if (missing.count(key))
      s << "n/a (" << missing.at(key) << ")";
    else
      s << v;
    return s.str();
  };
  const bool drag = !c.not_available.count("rotational_drag");
  std::ostringstream folded;
  folded.copyfmt(out);
  folded << (drag ? " folded in at " : ", moment balance judged without it");
  if (drag) folded << kRotationalDragTolerance;
  out << "  force balance " << m.force_balance << " (axial " << m.force_balance_yy << ", lateral x "
      << c.xz.force_balance_xx << ", lateral y " << c.yz.force_balance_xx << ", shear xz "
      << c.xz.force_balance_shear << ", yz " << c.yz.force_balance_shear << ", xy "
      << c.xy.force_balance_shear << ")\n"
      << "  moment balance " << m.moment_balance << " (xz " << c.xz.moment_balance << ", yz "
      << c.yz.moment_balance << ", xy " << c.xy.moment_balance << "; rotational drag "
      << value(c.not_available, "rotational_drag", c.rotational_drag) << folded.str() << "), servo "
      << value(m.not_available, "servo", m.servo) << " (walls x min "
      << value(c.not_available, "servo_xmin", c.servo_walls[0]) << ", x max "
      << value(c.not_available, "servo_xmax", c.servo_walls[1]) << ", y min "
      << value(c.not_available, "servo_ymin", c.servo_walls[2]) << ", y max "
      << value(c.not_available, "servo_ymax", c.servo_walls[3]) << "), oscillation "
      << m.oscillation << "\n";
}

void print_peak(std::ostream& out, bool three_d, double peak, std::optional<double> strain,
                double sigma3) {
  out << "  peak b_" << (three_d ? "zz " : "yy ") << peak << " Pa";
  if (strain) out << " at strain " << *strain;
  out << " (sigma1/sigma3 " << -peak / sigma3;
}

std::string divergence_words(int64_t divergence_step, int64_t steps_planned) {
  std::string s = "diverged";
  if (divergence_step >= 0)
    s += " at step " + std::to_string(divergence_step) + " of " + std::to_string(steps_planned);
  return s;
}

void print_unscored_criteria(std::ostream& out, int64_t divergence_step, int64_t steps_planned,
                             const Criteria& c, bool rms) {
  out << "  criteria not scored: the run " << divergence_words(divergence_step, steps_planned);
  // c.points leaves out the consolidated start (a series' first row).
  out << ", " << c.points << (c.points == 1 ? " monitoring point" : " monitoring points")
      << " after the start";
  if (rms)
    out << " (over them: lateral force balance RMS " << c.force_balance_xx_rms << ", servo RMS "
        << c.servo_rms << ")";
  out << "\n";
}

}  // namespace demcal::cli
