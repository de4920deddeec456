// The demcal program: a thin command line over the library. Each
// subcommand lives in its own cmd_*.cpp.
#include <CLI/CLI.hpp>
#include <iostream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "commands.hpp"
#include "demcal/io/input_error.hpp"
#include "demcal/kernel/world.hpp"
#include "demcal/scene/config.hpp"

namespace {

/// `text` with every byte outside printable ASCII (a control character, a
/// byte of 0x80 and above) shown as \xNN: the kernel's message on a
/// DEMCAL_SIMD or DEMCAL_GATHER it cannot honour quotes the environment's value as it is,
/// and the one-line error must stay one readable line.
std::string printable(std::string_view text) {
  static const char* const kHex = "0123456789abcdef";
  std::string out;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7f) {
      out += ch;
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

/// A first word that is neither an option nor a command, named with the
/// commands there are (CLI11 says only that a subcommand is required); ""
/// when the first word is fine.
std::string unknown_command(const CLI::App& app, int argc, char** argv) {
  if (argc <= 1 || argv[1][0] == '-') return "";
  const std::string word = argv[1];
  std::string names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (sub->get_name() == word) return "";
    names += (names.empty() ? "" : ", ") + sub->get_name();
  }
  return "unknown command " + demcal::quoted_value(word) + "; the commands are " + names;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace demcal::cli;
  // Exit statuses: 0 ok, 1 the computation failed, 2 bad input.
  constexpr int kBadInput = 2;
  CLI::App app{
      "demcal: calibrate the algorithmic parameters (dt, steps, damping) of quasi-static "
      "DEM runs"};
  app.require_subcommand(1);
  const auto run_trial = add_trial_commands(app);  // check, run, sweep, calibrate, stability, score
  const auto run_upscaling = add_upscaling_commands(app);  // upscale, verify, scaling, export, rev

  if (const std::string error = unknown_command(app, argc, argv); !error.empty()) {
    std::cerr << "demcal: error: " << error << " (see --help)\n";
    return kBadInput;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints and exits 0; a usage error is bad input: one line, 2.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    std::cerr << "demcal: error: " << e.what() << " (see --help)\n";
    return kBadInput;
  }
  try {
    // A DEMCAL_SIMD or DEMCAL_GATHER the kernel cannot honour is bad
    // input, found before a command reads or writes anything (kernel_simd
    // makes both choices).
    try {
      demcal::kernel_simd();
    } catch (const std::invalid_argument& e) {
      throw demcal::InputError("environment", "", printable(e.what()));
    }
    if (const int status = run_trial(); status >= 0) return status;
    if (const int status = run_upscaling(); status >= 0) return status;
  } catch (const demcal::InputError& e) {
    std::cerr << "demcal: error: " << e.what() << "\n";
    return kBadInput;
  } catch (const std::exception& e) {
    std::cerr << "demcal: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
