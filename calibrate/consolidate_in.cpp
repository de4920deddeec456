#include "consolidate_in.hpp"

#include "demcal/io/input_error.hpp"

namespace demcal::cli {

bool consolidate_in_deck(const std::string& choice, const std::string& format, bool no_consolidate,
                         int particles) {
  if (choice != "auto" && choice != "demcal" && choice != "deck")
    throw InputError("--consolidate-in", "",
                     "must be demcal, deck or auto, got \"" + choice + "\"");
  if (choice == "deck" && format != "lammps")
    throw InputError("--consolidate-in", "", "deck: only the LAMMPS deck consolidates itself");
  if (choice != "auto" && no_consolidate)
    throw InputError("--consolidate-in", "",
                     "the prototype is not consolidated with --no-consolidate");
  (void)particles;  // no size makes the deck cheaper on the same cores
  return choice == "deck";
}

}  // namespace demcal::cli
